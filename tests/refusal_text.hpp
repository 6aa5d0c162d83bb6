// Tests' view of a validator as text: core's and the api's validators refuse as data
// (`Validate(Refusal*)`, core/refusal.hpp); a test that asserts the message a user sees reads
// it through Validates.
#pragma once

#include <string>

#include "core/refusal.hpp"

namespace sweetspot {

/// True when `checked.Validate` accepts it; otherwise false, with the refusal's Message()
/// ("field = value: rule") in *why (if non-null).
template <typename Checked>
bool Validates(const Checked& checked, std::string* why) {
  return core::ExplainRefusal(why,
                              [&checked](core::Refusal* out) { return checked.Validate(out); });
}

}  // namespace sweetspot
