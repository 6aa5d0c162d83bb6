// The one place where every backend's raw status becomes a backend-neutral Termination: NLopt
// result codes (used by the scalar search, the shape fit and the NLopt design backends), the
// exceptions NLopt's C++ wrapper throws for negative codes, and Ipopt's ApplicationReturnStatus.
// The solvers' headers stay in termination.cpp; this header speaks ints and std types only.
#pragma once

#include <exception>
#include <string>

#include "core/summary.hpp"

namespace sweetspot::core {

/// NLopt's result codes (nlopt_result values), for code that branches on them without NLopt's
/// header; their names are NloptResultName's.
constexpr int kNloptForcedStop = -5;       ///< FORCED_STOP.
constexpr int kNloptRoundoffLimited = -4;  ///< ROUNDOFF_LIMITED (x holds the best point).
constexpr int kNloptOutOfMemory = -3;      ///< OUT_OF_MEMORY.
constexpr int kNloptInvalidArgs = -2;      ///< INVALID_ARGS.
constexpr int kNloptFailure = -1;          ///< FAILURE.
constexpr int kNloptSuccess = 1;           ///< SUCCESS.
constexpr int kNloptStopvalReached = 2;    ///< STOPVAL_REACHED.
constexpr int kNloptFtolReached = 3;       ///< FTOL_REACHED.
constexpr int kNloptXtolReached = 4;       ///< XTOL_REACHED.
constexpr int kNloptMaxevalReached = 5;    ///< MAXEVAL_REACHED.
constexpr int kNloptMaxtimeReached = 6;    ///< MAXTIME_REACHED.

/// The backend-neutral outcome of an NLopt result code (nlopt_result values, -5 ... 6):
/// SUCCESS, STOPVAL, FTOL, XTOL -> kConverged; MAXEVAL, MAXTIME, ROUNDOFF_LIMITED (best point
/// kept) -> kNoConvergence; INVALID_ARGS -> kInvalidInput; FAILURE, OUT_OF_MEMORY, FORCED_STOP
/// and unknown codes -> kFailure.
Termination TerminationFromNloptResult(int raw_status);
/// NLopt's name of a result code ("SUCCESS", "ROUNDOFF_LIMITED", ...; "UNKNOWN" otherwise).
const char* NloptResultName(int raw_status);

/// The NLopt result code an exception from nlopt::opt::optimize() stands for (the exception
/// ladder): nlopt::roundoff_limited -> ROUNDOFF_LIMITED (-4; the point NLopt left is the best
/// one and is kept), nlopt::forced_stop -> FORCED_STOP (-5), std::invalid_argument ->
/// INVALID_ARGS (-2), std::bad_alloc -> OUT_OF_MEMORY (-3), any other exception -> FAILURE (-1).
/// A description for the summary goes to *message (empty for round-off and forced stops).
/// Never throws; a null `error` is FAILURE.
int NloptResultFromException(const std::exception_ptr& error, std::string* message);

/// The backend-neutral outcome of an Ipopt ApplicationReturnStatus (every value of 3.11:
/// 0..6, -1..-4, -10..-13, -100..-102, -199); unknown codes map to kFailure.
Termination TerminationFromIpoptStatus(int raw_status);
/// Ipopt's name of a status ("Solve_Succeeded", ...; "Unknown" otherwise).
const char* IpoptStatusName(int raw_status);

}  // namespace sweetspot::core
