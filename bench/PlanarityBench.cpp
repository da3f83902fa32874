// Per-face planarity of a whole mesh, per backend, on generated planar-quad meshes
// from the Yas Island scale (~4k faces) to 1M faces.
#include <benchmark/benchmark.h>

#include <cmath>

#include "compute/Backend.h"
#include "mesh/Generators.h"

namespace {

void BM_FacePlanarity(benchmark::State& state, plano::compute::BackendChoice choice) {
  const auto side = static_cast<plano::Index>(std::lround(std::sqrt(static_cast<double>(state.range(0)))));
  const plano::PolygonMesh mesh = plano::generate::translationalSurface(side, side);
  std::unique_ptr<plano::compute::Backend> backend;
  try {
    backend = plano::compute::createBackend(choice);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  std::vector<double> values(mesh.faceCount());
  for (auto _ : state) {
    backend->facePlanarity(mesh, values);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["faces"] = mesh.faceCount();
  state.counters["faces_per_s"] =
      benchmark::Counter(static_cast<double>(mesh.faceCount()), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK_CAPTURE(BM_FacePlanarity, cpu, plano::compute::BackendChoice::Cpu)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FacePlanarity, vulkan, plano::compute::BackendChoice::Vulkan)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);

}  // namespace
