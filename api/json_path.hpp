// Dotted paths into a request's JSON ("fill.depth_m", "profile.knots[3].radius_m"),
// used by /v1/explore parameters and /v1/optimize variables.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace sweetspot::api {

/// One step of a path: an object key or an array index.
using PathStep = std::variant<std::string, std::size_t>;

/// Parses "a.b[2].c" into steps; nullopt with the reason in *why on bad syntax.
std::optional<std::vector<PathStep>> ParseJsonPath(const std::string& path, std::string* why);

/// The path of `steps` written as ParseJsonPath reads it ("a.b[2].c").
std::string FormatJsonPath(const std::vector<PathStep>& steps);

/// The number at `steps` in `root`, or nullopt (with *why) when the path does
/// not exist or does not hold a number.
std::optional<double> NumberAtPath(const nlohmann::json& root, const std::vector<PathStep>& steps,
                                   std::string* why);

/// Sets the number at `steps` in `root`. Every object and array on the way
/// must exist; the last key may be new (its object must exist); an array
/// index must be in range. Returns false with the reason in *why otherwise.
bool SetNumberAtPath(nlohmann::json* root, const std::vector<PathStep>& steps, double value,
                     std::string* why);

}  // namespace sweetspot::api
