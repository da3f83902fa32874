// Per-face planarity of a whole mesh, per backend, on generated planar-quad meshes from
// the Yas Island scale (~4k faces) to 1M faces. Vulkan times include the upload of the
// mesh and the read-back of the values (what Backend::facePlanarity costs a caller).
#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"

namespace {

using plano::compute::BackendChoice;

void BM_FacePlanarity(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  std::vector<double> values(mesh.faceCount());
  for (auto _ : state) {
    backend->facePlanarity(mesh, values);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["faces"] = mesh.faceCount();
  plano::bench::setThroughput(state, mesh.faceCount());
}

BENCHMARK_CAPTURE(BM_FacePlanarity, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_FacePlanarity, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_FacePlanarity, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_FacePlanarity, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);

}  // namespace
