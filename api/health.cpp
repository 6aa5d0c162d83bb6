#include "api/response.hpp"

namespace sweetspot::api {

Response HandleHealth() { return {200, nlohmann::json{{"status", "ok"}}}; }

}  // namespace sweetspot::api
