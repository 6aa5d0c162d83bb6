// Termination mapping of every backend (see termination.hpp): the only place that turns NLopt
// result codes, NLopt's exceptions and Ipopt's ApplicationReturnStatus into a Termination.
#include "core/numerics/termination.hpp"

#include <new>
#include <stdexcept>

#include <coin/IpReturnCodes.hpp>
#include <nlopt.hpp>

namespace sweetspot::core {

static_assert(kNloptForcedStop == NLOPT_FORCED_STOP &&
                  kNloptRoundoffLimited == NLOPT_ROUNDOFF_LIMITED &&
                  kNloptOutOfMemory == NLOPT_OUT_OF_MEMORY &&
                  kNloptInvalidArgs == NLOPT_INVALID_ARGS && kNloptFailure == NLOPT_FAILURE &&
                  kNloptSuccess == NLOPT_SUCCESS && kNloptStopvalReached == NLOPT_STOPVAL_REACHED &&
                  kNloptFtolReached == NLOPT_FTOL_REACHED &&
                  kNloptXtolReached == NLOPT_XTOL_REACHED &&
                  kNloptMaxevalReached == NLOPT_MAXEVAL_REACHED &&
                  kNloptMaxtimeReached == NLOPT_MAXTIME_REACHED,
              "termination.hpp's NLopt codes are NLopt's");

Termination TerminationFromNloptResult(int raw_status) {
  switch (raw_status) {
    case 1:  // SUCCESS
    case 2:  // STOPVAL_REACHED
    case 3:  // FTOL_REACHED
    case 4:  // XTOL_REACHED
      return Termination::kConverged;
    case 5:   // MAXEVAL_REACHED
    case 6:   // MAXTIME_REACHED
    case -4:  // ROUNDOFF_LIMITED: the best point is kept
      return Termination::kNoConvergence;
    case -2:  // INVALID_ARGS
      return Termination::kInvalidInput;
    case -1:  // FAILURE
    case -3:  // OUT_OF_MEMORY
    case -5:  // FORCED_STOP (only ever forced by us after an objective failure)
    default:
      return Termination::kFailure;
  }
}

const char* NloptResultName(int raw_status) {
  switch (raw_status) {
    case -1:
      return "FAILURE";
    case -2:
      return "INVALID_ARGS";
    case -3:
      return "OUT_OF_MEMORY";
    case -4:
      return "ROUNDOFF_LIMITED";
    case -5:
      return "FORCED_STOP";
    case 1:
      return "SUCCESS";
    case 2:
      return "STOPVAL_REACHED";
    case 3:
      return "FTOL_REACHED";
    case 4:
      return "XTOL_REACHED";
    case 5:
      return "MAXEVAL_REACHED";
    case 6:
      return "MAXTIME_REACHED";
    default:
      return "UNKNOWN";
  }
}

int NloptResultFromException(const std::exception_ptr& error, std::string* message) {
  std::string text;
  int raw = NLOPT_FAILURE;
  try {
    if (error) std::rethrow_exception(error);
    text = "NLopt failed: no exception";
  } catch (const nlopt::roundoff_limited&) {
    raw = NLOPT_ROUNDOFF_LIMITED;  // the point NLopt left is its best: the caller keeps it
  } catch (const nlopt::forced_stop&) {
    raw = NLOPT_FORCED_STOP;
  } catch (const std::invalid_argument& e) {
    raw = NLOPT_INVALID_ARGS;
    text = std::string("NLopt refused the problem: ") + e.what();
  } catch (const std::bad_alloc&) {
    raw = NLOPT_OUT_OF_MEMORY;
    text = "NLopt ran out of memory";
  } catch (const std::exception& e) {
    raw = NLOPT_FAILURE;
    text = std::string("NLopt failed: ") + e.what();
  } catch (...) {
    raw = NLOPT_FAILURE;
    text = "NLopt failed: an unknown exception";
  }
  if (message != nullptr) *message = text;
  return raw;
}

Termination TerminationFromIpoptStatus(int raw_status) {
  switch (raw_status) {
    case Ipopt::Solve_Succeeded:
    case Ipopt::Solved_To_Acceptable_Level:
      return Termination::kConverged;
    case Ipopt::Infeasible_Problem_Detected:
      return Termination::kInfeasible;
    case Ipopt::Search_Direction_Becomes_Too_Small:
    case Ipopt::User_Requested_Stop:
    case Ipopt::Feasible_Point_Found:
    case Ipopt::Maximum_Iterations_Exceeded:
    case Ipopt::Maximum_CpuTime_Exceeded:
      return Termination::kNoConvergence;
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
    case Ipopt::Invalid_Problem_Definition:
    case Ipopt::Invalid_Option:
      return Termination::kInvalidInput;
    case Ipopt::Diverging_Iterates:
    case Ipopt::Restoration_Failed:
    case Ipopt::Error_In_Step_Computation:
    case Ipopt::Invalid_Number_Detected:
    case Ipopt::Unrecoverable_Exception:
    case Ipopt::NonIpopt_Exception_Thrown:
    case Ipopt::Insufficient_Memory:
    case Ipopt::Internal_Error:
      return Termination::kFailure;
  }
  return Termination::kFailure;
}

const char* IpoptStatusName(int raw_status) {
  switch (raw_status) {
    case Ipopt::Solve_Succeeded:
      return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates:
      return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop:
      return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found:
      return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed:
      return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option:
      return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception:
      return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown:
      return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory:
      return "Insufficient_Memory";
    case Ipopt::Internal_Error:
      return "Internal_Error";
  }
  return "Unknown";
}

}  // namespace sweetspot::core
