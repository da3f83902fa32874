// Batched local-step kernels per backend: projective fits of every face (projective-maps
// paper §4.1), closest rotations and closest ideal maps (App. A), on generated quad meshes
// of ~4k to 1M faces.
// Vulkan times include uploads and read-backs (the Backend interface's cost).
#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/cpu/CpuBackend.h"

namespace {

using plano::compute::BackendChoice;

void BM_ProjectiveFits(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::Positions target = plano::bench::jittered(mesh.vertices, 0.1 / std::sqrt(double(state.range(0))));
  plano::compute::ProjectiveFits fits;
  for (auto _ : state) {
    backend->fitProjectiveMaps(mesh.faces, mesh.vertices, target, fits);
    benchmark::DoNotOptimize(fits.maps.data());
  }
  state.counters["faces"] = mesh.faceCount();
  plano::bench::setThroughput(state, mesh.faceCount());
}

void BM_ClosestRotations(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const auto count = static_cast<std::size_t>(state.range(0));  // one 3x3 matrix per face
  std::mt19937 rng(1);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix3d> matrices(count);
  for (auto& m : matrices) m = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return g(rng); });
  std::vector<Eigen::Matrix3d> rotations(count);
  std::vector<Eigen::Vector3d> singular(count);
  for (auto _ : state) {
    backend->closestRotations(matrices, rotations, singular);
    benchmark::DoNotOptimize(rotations.data());
  }
  state.counters["faces"] = static_cast<double>(count);
  plano::bench::setThroughput(state, static_cast<double>(count));
}

/// The rigid maps of a deformation's local step: from each face's fit (computed once, on
/// the CPU) through its in-plane Jacobian and closest rotation, the target given for the
/// corner-set fallback.
void BM_IdealMaps(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::Positions target = plano::bench::jittered(mesh.vertices, 0.1 / std::sqrt(double(state.range(0))));
  plano::compute::ProjectiveFits fits;
  plano::compute::CpuBackend().fitProjectiveMaps(mesh.faces, mesh.vertices, target, fits);
  plano::compute::IdealMaps ideal;
  for (auto _ : state) {
    backend->closestIdealMaps(mesh.faces, mesh.vertices, fits.maps, &target, false, ideal);
    benchmark::DoNotOptimize(ideal.maps.data());
  }
  state.counters["faces"] = mesh.faceCount();
  plano::bench::setThroughput(state, mesh.faceCount());
}

BENCHMARK_CAPTURE(BM_ProjectiveFits, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ProjectiveFits, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_ProjectiveFits, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ProjectiveFits, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_ClosestRotations, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ClosestRotations, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_ClosestRotations, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ClosestRotations, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_IdealMaps, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_IdealMaps, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_IdealMaps, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_IdealMaps, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);

}  // namespace
