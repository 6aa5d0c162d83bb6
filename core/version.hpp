// Versions of sweetspot and of the libraries it was built against, for the
// provenance block of every solver result.
#pragma once

#include <string>

namespace sweetspot::core {

/// The service's own version, "MAJOR.MINOR.PATCH".
std::string SweetspotVersion();
/// Eigen's version as compiled in, e.g. "3.4.0".
std::string EigenVersion();
/// NLopt's version as reported by the linked library, e.g. "2.7.1".
std::string NloptVersion();
/// Ipopt's version as compiled in, e.g. "3.11.9".
std::string IpoptVersion();

}  // namespace sweetspot::core
