// The endpoint handlers: pure functions (request, context) -> Response.
// Each parses and validates strictly, calls core, and renders the result.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "api/json_reader.hpp"
#include "api/json_writer.hpp"
#include "api/router.hpp"

namespace sweetspot::api {

/// GET /openapi.json: the OpenAPI 3 document (docs/openapi.json, embedded).
Response HandleOpenApi(const Request& request, const Context& context);
/// GET /metrics: Prometheus text from the server (501 where there is no server).
Response HandleMetrics(const Request& request, const Context& context);
/// GET /v1/version: versions of sweetspot and its libraries, and the speed-vs-error report's date.
Response HandleVersion(const Request& request, const Context& context);
/// GET /v1/speed-vs-error: the speed-versus-error report (docs/speed-vs-error.json, embedded):
/// time per evaluation (s) against error for every model and numeric setting.
Response HandleSpeedVsError(const Request& request, const Context& context);
/// When the embedded speed-vs-error report was generated (UTC, ISO 8601), or null.
nlohmann::json SpeedVsErrorGenerated();
/// GET /v1/materials: the material catalogue with sources.
Response HandleMaterials(const Request& request, const Context& context);
/// GET /v1/presets: the preset bats with their properties and sources.
Response HandlePresets(const Request& request, const Context& context);
/// GET /v1/balls: the ball catalogue (mass, radius, COR law, contact law) with sources.
Response HandleBalls(const Request& request, const Context& context);
/// POST /v1/bat/properties: exact mass properties of a bat.
Response HandleBatProperties(const Request& request, const Context& context);
/// POST /v1/bat/fit: unknown dimensions from target mass and balance point.
Response HandleBatFit(const Request& request, const Context& context);
/// POST /v1/sweet-spot: the requested sweet-spot outputs of a scene.
Response HandleSweetSpot(const Request& request, const Context& context);
/// POST /v1/collision: one impact with a chosen model.
Response HandleCollision(const Request& request, const Context& context);
/// POST /v1/flight: batted-ball flight from launch conditions to the landing point
/// (core/flight), for one launch or many.
Response HandleFlight(const Request& request, const Context& context);
/// POST /v1/compare: a baseline bat against variants in one scene.
Response HandleCompare(const Request& request, const Context& context);
/// POST /v1/optimize: Ipopt bat design (501 until the optimisation issue lands).
Response HandleOptimize(const Request& request, const Context& context);
/// POST /v1/explore: design sweeps (501 until the optimisation issue lands).
Response HandleExplore(const Request& request, const Context& context);
/// POST /v1/jobs: run a long request as a job, once its endpoint's parser accepted it.
Response HandleJobSubmit(const Request& request, const Context& context);
/// GET /v1/jobs/{id}: a job's state and progress.
Response HandleJobStatus(const Request& request, const Context& context);
/// GET /v1/jobs?state=&limit=&offset=: {"jobs": [...], "total", "next_offset"}, the jobs the
/// server keeps, newest submitted first (api/job_service.hpp's JobListQuery); 400 for a bad query.
Response HandleJobList(const Request& request, const Context& context);
/// GET /v1/jobs/{id}/result: a finished job's result.
Response HandleJobResult(const Request& request, const Context& context);
/// DELETE /v1/jobs/{id}: cancel (or forget) a job.
Response HandleJobCancel(const Request& request, const Context& context);

/// A hash of a request's canonical JSON (sorted keys, compact): "fnv1a64:<16 hex>".
std::string InputHash(const nlohmann::json& canonical_input);

/// The provenance block of a solver result: versions, input hash, options, seed.
nlohmann::json Provenance(const nlohmann::json& input, const nlohmann::json& options,
                          std::optional<unsigned long long> seed = std::nullopt);
/// The same members written to `out` (api/json_writer.hpp's Out: TreeObject or TextObject).
template <class Out>
void WriteProvenance(const nlohmann::json& input, const nlohmann::json& options,
                     std::optional<unsigned long long> seed, Out& out);

/// Parses a POST body into a JSON object; on failure the error response.
std::optional<nlohmann::json> ParseObjectBody(const Request& request, const Context& context,
                                              Response* error_response);

}  // namespace sweetspot::api
