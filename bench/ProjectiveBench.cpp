// The projective shape space per backend: the batched local step, one global step
// (factorization + ADMM + polish) and one deformation iteration (local step, closest
// rigid maps, global step) on generated planar-quad grids of ~4k and ~64k faces (the
// global step also on ~1k, where the device ADMM runs in one workgroup on lavapipe).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>

#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/Admm.h"
#include "compute/Backend.h"
#include "mesh/Generators.h"
#include "projective/Deformation.h"
#include "projective/GlobalStep.h"
#include "projective/LocalStep.h"

namespace {

using plano::Index;
using plano::compute::BackendChoice;

plano::PolygonMesh grid(benchmark::State& state) {
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(state.range(0)))));
  return plano::generate::translationalSurface(side, side);
}

void setCounters(benchmark::State& state, const plano::PolygonMesh& mesh) {
  state.counters["faces"] = mesh.faceCount();
}

/// A projective image of the grid: every face has a nontrivial exact fit.
plano::Positions perspectiveTarget(const plano::projective::ShapeSpace& space) {
  Eigen::Matrix4d H;
  H << 0.9, 0.2, -0.1, 0.08, -0.15, 1.1, 0.05, -0.06, 0.1, -0.05, 0.95, 0.1, 0.3, -0.2, 0.4, 1.0;
  plano::Positions q(space.vertexCount(), 3);
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const Eigen::RowVector4d h = plano::projective::homogeneous(space.basePositions().row(v)) * H;
    q.row(v) = h.head<3>() / h[3];
  }
  return space.normalization().toWorld(q);
}

void BM_LocalStep(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = grid(state);
  const plano::projective::ShapeSpace space(mesh);
  const plano::Positions target = perspectiveTarget(space);
  for (auto _ : state) {
    auto result = plano::projective::fitFaceMaps(*backend, space, target);
    benchmark::DoNotOptimize(result.fits.maps.data());
  }
  setCounters(state, mesh);
}

/// Rigid targets that disagree (a rotation on every other face) with the row v = 0 fixed:
/// a global step that needs real ADMM work.
void BM_GlobalStep(benchmark::State& state, BackendChoice choice,
                   plano::compute::AdmmPreconditioner preconditioner = plano::compute::AdmmPreconditioner::Automatic) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = grid(state);
  const plano::projective::ShapeSpace space(mesh);
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  std::vector<Index> fixed;
  for (Index i = 0; i <= side; ++i) fixed.push_back(i * (side + 1));
  plano::Positions at(fixed.size(), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(i) = mesh.vertices.row(fixed[i]);
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index f = 0; f < space.faceCount(); f += 2) targets[f].topLeftCorner<3, 3>() = R;
  plano::projective::GlobalStepSettings settings;
  settings.epsilonStart = plano::projective::EpsilonStart::ExactFirst;
  settings.qp.preconditioner = preconditioner;
  plano::projective::GlobalStep global(*backend, space, fixed, settings);
  plano::projective::FaceMaps result;
  plano::projective::GlobalStepInfo info;
  for (auto _ : state) {
    info = global.solve(targets, at, result);
    benchmark::DoNotOptimize(result.maps.data());
  }
  setCounters(state, mesh);
  state.counters["admm_iterations"] = info.admmIterations;
  state.counters["factorizations"] = info.factorizations;
  state.counters["linear_iterations"] = static_cast<double>(info.linearIterations);
}

/// One as-rigid-as-possible iteration: fixed row, corner handle lifted.
void BM_DeformationIteration(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = grid(state);
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  plano::PositionalConstraints constraints;
  for (Index i = 0; i <= side; ++i) constraints.fixed.push_back(i * (side + 1));
  const Index corner = mesh.vertexCount() - 1;
  constraints.handles.push_back({corner, mesh.vertices.row(corner).transpose() + Eigen::Vector3d(0.1, 0.1, 0.3)});
  plano::projective::DeformationSettings settings;
  settings.maxIterations = 1;
  settings.maxProjectionIterations = 0;
  plano::projective::Deformation deformation(*backend, mesh, constraints, settings);
  plano::Positions handles(1, 3);
  handles.row(0) = constraints.handles[0].position.transpose();
  int admm = 0;
  for (auto _ : state) {
    plano::Positions positions = mesh.vertices;
    const auto info = deformation.solve(handles, positions);
    admm = info.history.empty() ? 0 : info.history.back().admmIterations;
    benchmark::DoNotOptimize(positions.data());
  }
  setCounters(state, mesh);
  state.counters["admm_iterations"] = admm;
}

BENCHMARK_CAPTURE(BM_LocalStep, cpu, BackendChoice::Cpu)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LocalStep, vulkan, BackendChoice::Vulkan)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
// On lavapipe the device global step finishes up to about 1k faces (101 s with the multigrid
// preconditioner, the default above 64 faces); vulkan_face_blocks is the block-Jacobi baseline.
BENCHMARK_CAPTURE(BM_GlobalStep, cpu, BackendChoice::Cpu)
    ->Arg(64)->Arg(256)->Arg(1024)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan_face_blocks, BackendChoice::Vulkan,
                  plano::compute::AdmmPreconditioner::BlockJacobi)
    ->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan, BackendChoice::Vulkan)
    ->Arg(64)->Arg(256)->Arg(1024)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, cpu, BackendChoice::Cpu)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, vulkan, BackendChoice::Vulkan)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);

}  // namespace
