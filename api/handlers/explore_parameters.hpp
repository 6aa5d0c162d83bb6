// /v1/explore's swept parameters: each parameter of the request read and its paths bound into
// the design template (explore_parameters.cpp), for the request's parser (explore_request.cpp).
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>

#include "api/explore/binder.hpp"
#include "api/json_reader.hpp"
#include "api/router.hpp"
#include "core/explore/sampling.hpp"

namespace sweetspot::api::explore_detail {

/// parameters[i] of an explore request (`item`): its paths ("path", or "paths" set to one value,
/// or "scale_paths" scaled by it; a trade unit swept as its SI field) bound into *parameter,
/// each checked against the template *base (which may gain a scene object left to its
/// defaults, or a preset's knots), and its range "min", "max" (in the paths' units) and grid
/// "count" (default 2 for a grid, else 1) into *dimension. False with *error set (400).
bool ParseSweepParameter(const nlohmann::json& item, std::size_t i, core::SamplingMethod method,
                         const Context& context, nlohmann::json* base, SweepParameter* parameter,
                         core::SweepDimension* dimension, ApiError* error);

}  // namespace sweetspot::api::explore_detail
