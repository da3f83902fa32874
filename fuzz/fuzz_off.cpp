// libFuzzer target: the OFF reader (see FuzzMesh.h for what counts as a failure).
#include "FuzzMesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return plano::fuzz::fuzzMesh(data, size, plano::MeshFormat::Off);
}
