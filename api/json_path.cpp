#include "api/json_path.hpp"

#include <cctype>

namespace sweetspot::api {
namespace {

std::string StepText(const std::vector<PathStep>& steps, std::size_t upto) {
  std::string out;
  for (std::size_t i = 0; i < upto && i < steps.size(); ++i) {
    // append() rather than operator+ chains: GCC 12 warns (-Wrestrict) falsely on those.
    if (const auto* key = std::get_if<std::string>(&steps[i])) {
      if (!out.empty()) out.push_back('.');
      out.append(*key);
    } else {
      out.push_back('[');
      out.append(std::to_string(std::get<std::size_t>(steps[i])));
      out.push_back(']');
    }
  }
  return out;
}

}  // namespace

std::optional<std::vector<PathStep>> ParseJsonPath(const std::string& path, std::string* why) {
  std::vector<PathStep> steps;
  std::size_t i = 0;
  auto fail = [&](const std::string& rule) -> std::optional<std::vector<PathStep>> {
    if (why != nullptr) *why = rule + " at character " + std::to_string(i);
    return std::nullopt;
  };
  if (path.empty()) return fail("is empty");
  while (i < path.size()) {
    std::string key;
    while (i < path.size() && path[i] != '.' && path[i] != '[') {
      const char c = path[i];
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) {
        return fail("has an invalid character");
      }
      key += c;
      ++i;
    }
    if (key.empty()) return fail("has an empty key");
    steps.emplace_back(key);
    while (i < path.size() && path[i] == '[') {
      ++i;
      std::size_t index = 0;
      const std::size_t start = i;
      while (i < path.size() && std::isdigit(static_cast<unsigned char>(path[i]))) {
        if (i - start > 6) return fail("has an index that is too large");
        index = index * 10 + static_cast<std::size_t>(path[i] - '0');
        ++i;
      }
      if (i == start || i >= path.size() || path[i] != ']') return fail("has a malformed [index]");
      ++i;
      steps.emplace_back(index);
    }
    if (i < path.size()) {
      if (path[i] != '.') return fail("expects '.'");
      ++i;
      if (i == path.size()) return fail("ends with '.'");
    }
  }
  return steps;
}

std::optional<double> NumberAtPath(const nlohmann::json& root, const std::vector<PathStep>& steps,
                                   std::string* why) {
  const nlohmann::json* node = &root;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (const auto* key = std::get_if<std::string>(&steps[i])) {
      if (!node->is_object() || !node->contains(*key)) {
        if (why != nullptr) *why = "the request has no field " + StepText(steps, i + 1);
        return std::nullopt;
      }
      node = &(*node)[*key];
    } else {
      const std::size_t index = std::get<std::size_t>(steps[i]);
      if (!node->is_array() || index >= node->size()) {
        if (why != nullptr) *why = "the request has no element " + StepText(steps, i + 1);
        return std::nullopt;
      }
      node = &(*node)[index];
    }
  }
  if (!node->is_number()) {
    if (why != nullptr) *why = StepText(steps, steps.size()) + " is not a number";
    return std::nullopt;
  }
  return node->get<double>();
}

bool SetNumberAtPath(nlohmann::json* root, const std::vector<PathStep>& steps, double value,
                     std::string* why) {
  nlohmann::json* node = root;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const bool last = i + 1 == steps.size();
    if (const auto* key = std::get_if<std::string>(&steps[i])) {
      if (!node->is_object()) {
        if (why != nullptr) *why = StepText(steps, i) + " is not an object";
        return false;
      }
      if (!node->contains(*key) && !last) {
        if (why != nullptr) {
          *why = "the request has no field " + StepText(steps, i + 1) + " (give it in the request)";
        }
        return false;
      }
      node = &(*node)[*key];
    } else {
      const std::size_t index = std::get<std::size_t>(steps[i]);
      if (!node->is_array() || index >= node->size()) {
        if (why != nullptr) *why = "the request has no element " + StepText(steps, i + 1);
        return false;
      }
      node = &(*node)[index];
    }
  }
  if (!node->is_null() && !node->is_number()) {
    if (why != nullptr) *why = StepText(steps, steps.size()) + " is not a number";
    return false;
  }
  *node = value;
  return true;
}

std::string FormatJsonPath(const std::vector<PathStep>& steps) {
  std::string out;
  for (const PathStep& step : steps) {
    if (const auto* key = std::get_if<std::string>(&step)) {
      if (!out.empty()) out += '.';
      out += *key;
    } else {
      out += '[';  // appended piece by piece: GCC 12 warns (falsely) on "[" + to_string(i)
      out += std::to_string(std::get<std::size_t>(step));
      out += ']';
    }
  }
  return out;
}

}  // namespace sweetspot::api
