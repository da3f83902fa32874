// libFuzzer target: the positional-constraints parser. Malformed JSON is refused by the
// JSON parser (no exception here: the tool reports it separately); any parsed JSON value
// must either give constraints within range or be refused with plano::Error.
#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "core/Error.h"
#include "mesh/Constraints.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto json = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) return 0;
  constexpr plano::Index kVertexCount = 64;
  std::string warnings;
  try {
    const auto constraints = plano::parseConstraints(json, kVertexCount, &warnings, "fuzz");
    for (plano::Index v : constraints.fixed) {
      if (v < 0 || v >= kVertexCount) std::abort();
    }
    for (const auto& h : constraints.handles) {
      if (h.vertex < 0 || h.vertex >= kVertexCount || !h.position.allFinite()) std::abort();
    }
  } catch (const plano::Error&) {
  }
  return 0;
}
