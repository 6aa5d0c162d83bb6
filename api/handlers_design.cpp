// POST /v1/optimize: its core (Ipopt design) lands with the optimisation
// issue; until then it answers 501 with what is missing, never a made-up result.
#include "api/handlers.hpp"

namespace sweetspot::api {

Response HandleOptimize(const Request&, const Context&) {
  return ErrorResponse(501, "NotImplemented",
                       "POST /v1/optimize needs the Ipopt design model, which is not "
                       "available in this version");
}

}  // namespace sweetspot::api
