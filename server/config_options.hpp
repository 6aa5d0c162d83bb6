// The tables of the server's options (server/config.hpp), one per area, and the parsers
// their setters share. ParseCommandLine and Usage (config.cpp) read them in this order:
//   ServingOptions()  listening, threads (config_options.cpp)
//   ConnectionOptions()  connections, first byte, computing time, token, CORS (config_options.cpp)
//   RequestReadingOptions()  head and body sizes and deadlines, keep-alive (config_options.cpp)
//   LimitOptions()    request limits: bodies, JSON, arrays, samples, solvers (config_limits.cpp)
//   JobOptions()      the job pool and its store (config_limits.cpp)
//   ProcessOptions()  stopping (drain, grace), the web root, the access log (config.cpp)
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "server/config.hpp"

namespace sweetspot::server::config_options {

/// One option: flag name, environment variable, help text, and a setter that parses the text
/// into the config (returns false with a rule on bad text).
struct Option {
  const char* flag;
  const char* env;
  const char* help;
  bool takes_value;
  std::function<bool(ServerConfig*, const std::string&, std::string* rule)> set;
};

/// An integer in [lo, hi].
bool ParseLong(const std::string& text, long long lo, long long hi, long long* out,
               std::string* rule);
/// A number of seconds in (0, 3600].
bool ParseSeconds(const std::string& text, double* out, std::string* rule);
/// A number of seconds in (0, max].
bool ParseSecondsUpTo(const std::string& text, double max, double* out, std::string* rule);
/// A number of seconds in [0, 3600] (0 = none).
bool ParseSecondsOrZero(const std::string& text, double* out, std::string* rule);
/// 1, 0, true, false, yes, no, on, off.
bool ParseBool(const std::string& text, bool* out, std::string* rule);
/// A size in [1, 1e8].
bool SetSize(std::size_t* out, const std::string& text, std::string* rule);

const std::vector<Option>& ServingOptions();
const std::vector<Option>& ConnectionOptions();
const std::vector<Option>& RequestReadingOptions();
const std::vector<Option>& LimitOptions();
const std::vector<Option>& JobOptions();
const std::vector<Option>& ProcessOptions();

}  // namespace sweetspot::server::config_options
