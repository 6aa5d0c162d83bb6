#include "core/version.hpp"

#include <IpoptConfig.h>
#include <nlopt.hpp>

#include <Eigen/Core>

namespace sweetspot::core {

std::string SweetspotVersion() { return SWEETSPOT_VERSION; }

std::string EigenVersion() {
  return std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
         "." + std::to_string(EIGEN_MINOR_VERSION);
}

std::string NloptVersion() {
  int major = 0, minor = 0, bugfix = 0;
  nlopt::version(major, minor, bugfix);
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(bugfix);
}

std::string IpoptVersion() { return IPOPT_VERSION; }

}  // namespace sweetspot::core
