// Linear spaces of polyhedral meshes (linear-spaces paper, §4 "Implementation details":
// "less than a second for meshes with approximately a thousand faces"): building B, its
// null-space basis, K = 10 eigenshapes and one subspace ASAP iteration, on translational
// surfaces of ~1k, ~10k and ~100k planar quads. Each stage is timed on its own: the
// inputs of a stage are prepared outside the timed loop.
//
// Sizes left out, and why: the basis is dense (3#V x d), so 100k faces is run for the
// separable affine space only; eigenshapes and deformation need N^T L N (#V d^2), which
// is run up to 10k faces.
#include <benchmark/benchmark.h>

#include <cmath>

#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "subspace/Eigenshapes.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "subspace/SparseShapes.h"
#include "subspace/SubspaceDeformation.h"

namespace {

using namespace plano;
using namespace plano::subspace;

PolygonMesh gridOfFaces(std::int64_t faces) {
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(faces))));
  return generate::translationalSurface(side, side);
}

void BM_ConstraintMatrix(benchmark::State& state, SpaceKind kind) {
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const auto spaces = uniformAssignment(kind, mesh.faceCount());
  for (auto _ : state) {
    ConstraintMatrix B = buildConstraintMatrix(mesh, spaces);
    benchmark::DoNotOptimize(B.matrix.nonZeros());
  }
  state.counters["faces"] = mesh.faceCount();
}

void BM_NullSpaceBasis(benchmark::State& state, SpaceKind kind) {
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const ConstraintMatrix B = buildConstraintMatrix(mesh, uniformAssignment(kind, mesh.faceCount()));
  Index dimension = 0;
  for (auto _ : state) {
    const SubspaceBasis N = computeNullSpaceBasis(B);
    dimension = N.dimension();
    benchmark::DoNotOptimize(N.columns().data());
  }
  state.counters["faces"] = mesh.faceCount();
  state.counters["dimension"] = dimension;
}

void BM_Eigenshapes(benchmark::State& state, SpaceKind kind) {
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
  const compute::SparseMatrix L = uniformLaplacian(mesh.faces, mesh.vertexCount());
  EigenshapeSettings settings;
  settings.count = 10;
  for (auto _ : state) {
    const Eigenshapes shapes = computeEigenshapes(space.N, L, settings);
    benchmark::DoNotOptimize(shapes.frequencies.data());
  }
  state.counters["faces"] = mesh.faceCount();
  state.counters["dimension"] = space.N.dimension();
}

/// One sparse shape (OMP, linear-spaces paper §3) seeded at the grid's middle vertex moving
/// along z, up to the default 64 moving vertices; B is built outside the timed loop.
void BM_SparseShape(benchmark::State& state, SpaceKind kind) {
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const ConstraintMatrix B = buildConstraintMatrix(mesh, uniformAssignment(kind, mesh.faceCount()));
  const Index side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  const Index middle = (side / 2) * (side + 1) + side / 2;
  SparseShapeInfo info;
  for (auto _ : state) {
    const Positions X = sparseShape(B, middle, Eigen::Vector3d::UnitZ(), {}, &info);
    benchmark::DoNotOptimize(X.data());
  }
  state.counters["faces"] = mesh.faceCount();
  state.counters["omp_steps"] = static_cast<double>(info.iterations);
  state.counters["moving_vertices"] = static_cast<double>(info.supportVertices);
  state.counters["residual"] = info.residual;
}

/// One local/global iteration, after the precomputation (which is reported separately
/// as BM_DeformationPrecompute).
void BM_SubspaceDeformationIteration(benchmark::State& state, SpaceKind kind, compute::BackendChoice choice) {
  compute::Backend* backend = bench::backendOrSkip(state, choice);
  if (!backend) return;
  bench::MemoryCounters memory(state, backend);
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
  const Index side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  PositionalConstraints constraints;
  for (Index i = 0; i <= side; ++i) constraints.fixed.push_back(i);  // One boundary row.
  const Index centre = (side / 2) * (side + 1) + side / 2;
  constraints.handles.push_back({centre, mesh.vertices.row(centre).transpose() + Eigen::Vector3d(0, 0, 0.1)});
  SubspaceDeformationSettings settings;
  settings.maxIterations = 8;  // one device block
  settings.tolerance = 0.0;
  SubspaceDeformer deformer(space, constraints, *backend, settings);
  Positions X = mesh.vertices;
  try {
    deformer.solve(X);  // the device uploads its problem on the first solve: outside the timing
  } catch (const Error& e) {
    state.SkipWithError(e.what());  // e.g. a basis larger than the device's buffer range
    return;
  }
  std::int64_t iterations = 0;
  memory.markLoopStart();
  for (auto _ : state) {
    X = mesh.vertices;
    iterations += deformer.solve(X).iterations;
    benchmark::DoNotOptimize(X.data());
  }
  state.SetItemsProcessed(iterations);  // items_per_second: local/global iterations per second
  state.counters["faces"] = mesh.faceCount();
  state.counters["dimension"] = space.N.dimension();
}

void BM_DeformationPrecompute(benchmark::State& state, SpaceKind kind) {
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
  PositionalConstraints constraints;
  constraints.fixed = {0, 1, 2};
  compute::CpuBackend backend;
  for (auto _ : state) {
    SubspaceDeformer deformer(space, constraints, backend);
    benchmark::DoNotOptimize(deformer.freeDimension());
  }
  state.counters["faces"] = mesh.faceCount();
}

/// The reduced operator N^T (L (x) I_k) N (Backend::reducedOperator): the d x d matrix
/// behind the eigenshapes, the subspace deformation's global matrix and the fundamental
/// shapes, whose 2 k #V d^2 multiply-adds dominate them once d reaches the hundreds. Per
/// backend on the standard mesh sizes, L the grid's uniform Laplacian and N a random
/// #V x 256 basis (k = 1: a separable space's scalar basis, dimension 768; a basis's values
/// do not change the work, and a real basis at 1M faces would take minutes to compute).
void BM_ReducedOperator(benchmark::State& state, compute::BackendChoice choice) {
  compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  constexpr Index columns = 256;
  const PolygonMesh mesh = gridOfFaces(state.range(0));
  const compute::SparseMatrix L = uniformLaplacian(mesh.faces, mesh.vertexCount());
  const Eigen::MatrixXd N = Eigen::MatrixXd::Random(mesh.vertexCount(), columns);
  for (auto _ : state) {
    try {
      const Eigen::MatrixXd R = backend->reducedOperator(L, N, 1);
      benchmark::DoNotOptimize(R.data());
    } catch (const Error& e) {  // a basis larger than the device's memory
      state.SkipWithError(e.what());
      return;
    }
  }
  const double flops = 2.0 * static_cast<double>(N.rows()) * columns * columns + 2.0 * L.nonZeros() * columns;
  state.counters["faces"] = static_cast<double>(mesh.faceCount());
  state.counters["columns"] = columns;
  state.counters["gflop_per_s"] = benchmark::Counter(flops * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  plano::bench::setThroughput(state, static_cast<double>(mesh.faceCount()));
}

BENCHMARK_CAPTURE(BM_ReducedOperator, cpu, compute::BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ReducedOperator, cpu, compute::BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_ReducedOperator, vulkan, compute::BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_ReducedOperator, vulkan, compute::BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);

BENCHMARK_CAPTURE(BM_ConstraintMatrix, affine, SpaceKind::Affine)
    ->Arg(1024)->Arg(10000)->Arg(100489)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ConstraintMatrix, parallel, SpaceKind::Parallel)
    ->Arg(1024)->Arg(10000)->Arg(100489)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ConstraintMatrix, vertical, SpaceKind::Vertical)
    ->Arg(1024)->Arg(10000)->Arg(100489)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_NullSpaceBasis, affine, SpaceKind::Affine)
    ->Arg(1024)->Arg(10000)->Arg(100489)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_NullSpaceBasis, parallel, SpaceKind::Parallel)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_NullSpaceBasis, vertical, SpaceKind::Vertical)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_CAPTURE(BM_Eigenshapes, affine, SpaceKind::Affine)->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Eigenshapes, parallel, SpaceKind::Parallel)->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_SparseShape, affine, SpaceKind::Affine)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SparseShape, affine, SpaceKind::Affine)
    ->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_SparseShape, vertical, SpaceKind::Vertical)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_DeformationPrecompute, affine, SpaceKind::Affine)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_SubspaceDeformationIteration, affine/cpu, SpaceKind::Affine, compute::BackendChoice::Cpu)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SubspaceDeformationIteration, affine/vulkan, SpaceKind::Affine, compute::BackendChoice::Vulkan)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SubspaceDeformationIteration, parallel/cpu, SpaceKind::Parallel, compute::BackendChoice::Cpu)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_SubspaceDeformationIteration, parallel/vulkan, SpaceKind::Parallel, compute::BackendChoice::Vulkan)
    ->Arg(1024)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
