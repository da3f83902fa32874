// Subdivision and multi-resolution editing: linear schemes (refinement topology + target
// positions) refined to ~4k, ~64k and ~1M faces; planar-quad subdivision; multires vs
// direct deformation at the Yas Island scale of the paper's Table 1.
#include <benchmark/benchmark.h>

#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/Backend.h"
#include "mesh/Generators.h"
#include "projective/Deformation.h"
#include "projective/MultiresDeformation.h"
#include "projective/PqSubdivision.h"
#include "projective/QuadRefinement.h"
#include "projective/SubdivisionSchemes.h"

namespace {

using plano::compute::BackendChoice;
using plano::projective::SubdivisionScheme;

/// A 32 x 32 translational surface refined `levels` times: 4^levels * 1024 faces.
void BM_LinearSubdivision(benchmark::State& state, SubdivisionScheme scheme) {
  const auto levels = static_cast<int>(state.range(0));
  const plano::PolygonMesh base = plano::generate::translationalSurface(32, 32);
  plano::Index faces = 0;
  for (auto _ : state) {
    plano::PolygonMesh mesh = base;
    for (int level = 0; level < levels; ++level) {
      const auto refinement = plano::projective::refineQuads(mesh.faces, mesh.vertexCount());
      mesh.vertices = plano::projective::linearSubdivision(scheme, mesh.faces, mesh.vertices, refinement);
      mesh.faces = refinement.fineFaces;
    }
    faces = mesh.faceCount();
    benchmark::DoNotOptimize(mesh.vertices.data());
  }
  state.counters["faces"] = static_cast<double>(faces);
  state.counters["faces_per_s"] =
      benchmark::Counter(static_cast<double>(faces), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK_CAPTURE(BM_LinearSubdivision, catmull_clark, SubdivisionScheme::CatmullClark)
    ->Arg(1)->Arg(3)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LinearSubdivision, four_point, SubdivisionScheme::FourPoint)
    ->Arg(1)->Arg(3)->Arg(5)->Unit(benchmark::kMillisecond);

}  // namespace

// ---- planar-quad subdivision (paper §5) ------------------------------------------

namespace {

/// PQ subdivision of a 32 x 32 translational surface (already a conjugate net: one
/// iteration per level, measuring the pipeline) and of the cube (Catmull-Clark targets far
/// from planar: the paper's Fig. 2 case, 6 * 4^levels faces), per backend. On lavapipe
/// only the cube's first level is run (24 faces, two local/global iterations; the second
/// level alone takes minutes there).
void BM_PqSubdivision(benchmark::State& state, bool cube, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh base = cube ? plano::generate::cube() : plano::generate::translationalSurface(32, 32);
  plano::projective::PqSubdivisionSettings settings;
  settings.levels = static_cast<int>(state.range(0));
  plano::projective::PqSubdivisionInfo info;
  for (auto _ : state) {
    const auto result = plano::projective::subdividePlanarQuads(*backend, base, settings);
    info = result.info;
    benchmark::DoNotOptimize(result.positions.back().data());
  }
  int admm = 0;
  for (const auto& level : info.levels) {
    for (const auto& iteration : level.iterations) admm += iteration.admmIterations;
  }
  state.counters["faces"] = static_cast<double>(info.levels.back().faces);
  state.counters["iterations"] = info.totalIterations;
  state.counters["admm_iterations"] = admm;
  state.counters["max_planarity_pct"] = info.levels.back().planarity.max;
}

BENCHMARK_CAPTURE(BM_PqSubdivision, translational, false, BackendChoice::Cpu)
    ->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_PqSubdivision, cube, true, BackendChoice::Cpu)
    ->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_PqSubdivision, cube_vulkan, true, BackendChoice::Vulkan)
    ->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

/// One planar-quad level at the standard sizes: the level that takes the cube's planar-quad
/// hierarchy (paper Fig. 2) to about `faces` faces (6 * 4^k: 6 144, 98 304, ...), from the
/// PQ mesh of the level below (made untimed, on the CPU). A real level of a hierarchy:
/// extraordinary vertices, targets whose non-planarity shrinks with the faces.
void BM_PqSubdivisionLevel(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  int levelsBelow = 0;
  for (std::int64_t faces = 6 * 4; 4 * faces <= 3 * state.range(0) / 2; faces *= 4) ++levelsBelow;
  plano::PolygonMesh base = plano::generate::cube();
  if (levelsBelow > 0) {
    plano::projective::PqSubdivisionSettings below;
    below.levels = levelsBelow;
    base = plano::projective::subdividePlanarQuads(*plano::compute::createBackend(BackendChoice::Cpu), base, below)
               .finestMesh();
  }
  const plano::bench::MemoryCounters memory(state, backend);
  plano::projective::PqSubdivisionSettings settings;
  settings.levels = 1;
  plano::projective::PqSubdivisionInfo info;
  for (auto _ : state) {
    const auto result = plano::projective::subdividePlanarQuads(*backend, base, settings);
    info = result.info;
    benchmark::DoNotOptimize(result.positions.back().data());
  }
  const auto& level = info.levels.back();
  int admm = 0;
  for (const auto& iteration : level.iterations) admm += iteration.admmIterations;
  state.counters["faces"] = static_cast<double>(level.faces);
  state.counters["iterations"] = static_cast<double>(level.iterations.size());
  state.counters["admm_iterations"] = admm;
  state.counters["max_planarity_pct"] = level.planarity.max;
  plano::bench::setThroughput(state, static_cast<double>(level.faces));
}

BENCHMARK_CAPTURE(BM_PqSubdivisionLevel, cpu, BackendChoice::Cpu)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(BM_PqSubdivisionLevel, vulkan, BackendChoice::Vulkan)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// ---- multi-resolution vs direct deformation (paper §6, Table 1) -------------------

/// Yas-Island scale: 16 x 16 = 256 coarse quads, two four-point PQ levels = 4096 fine quads;
/// the finest row y = 0 fixed, the far corner lifted by 0.3 (a tenth of the diagonal).
struct YasScale {
  plano::projective::PqSubdivisionResult subdivision;
  plano::PositionalConstraints constraints;

  static const YasScale& get() {
    static const YasScale instance = [] {
      auto backend = plano::compute::createBackend(plano::compute::BackendChoice::Cpu);
      plano::projective::PqSubdivisionSettings settings;
      settings.levels = 2;
      settings.scheme = plano::projective::SubdivisionScheme::FourPoint;
      settings.planarityTolerance = 0.5;
      YasScale s{plano::projective::subdividePlanarQuads(*backend, plano::generate::translationalSurface(16, 16), settings),
                 {}};
      const plano::Positions& x = s.subdivision.positions.back();
      for (plano::Index v = 0; v < x.rows(); ++v) {
        if (x(v, 1) < 1e-9) s.constraints.fixed.push_back(v);
      }
      plano::Index corner = 0;
      (x.rowwise() - Eigen::RowVector3d(1.0, 1.0, x(0, 2))).rowwise().squaredNorm().minCoeff(&corner);
      s.constraints.handles.push_back({corner, x.row(corner).transpose() + Eigen::Vector3d(0.0, 0.0, 0.3)});
      return s;
    }();
    return instance;
  }
};

void BM_MultiresDeform(benchmark::State& state) {
  const YasScale& yas = YasScale::get();
  auto backend = plano::compute::createBackend(plano::compute::BackendChoice::Cpu);
  plano::projective::MultiresInfo info;
  for (auto _ : state) {
    const auto result =
        plano::projective::multiresDeform(*backend, yas.subdivision.hierarchy, yas.subdivision.positions, yas.constraints);
    info = result.info;
    benchmark::DoNotOptimize(result.positions.data());
  }
  state.counters["level"] = info.level;
  state.counters["coarse_faces"] = static_cast<double>(info.coarseFaces);
  state.counters["fine_faces"] = static_cast<double>(info.fineFaces);
  state.counters["coarse_iterations"] = info.coarseIterations;
  state.counters["coarse_ms"] = 1e3 * info.coarseSeconds;
  state.counters["prolongation_ms"] = 1e3 * info.prolongationSeconds;
  state.counters["max_planarity_pct"] = info.planarity.max;
  state.counters["handle_error"] = info.maxHandleError;
}

void BM_DirectDeform(benchmark::State& state) {
  const YasScale& yas = YasScale::get();
  auto backend = plano::compute::createBackend(plano::compute::BackendChoice::Cpu);
  const plano::PolygonMesh fine = yas.subdivision.finestMesh();
  plano::projective::DeformationSettings settings;  // same stopping rule as the multires default
  settings.tolerance = plano::projective::MultiresSettings{}.tolerance;
  settings.planarityTolerance = plano::projective::MultiresSettings{}.planarityTolerance;
  plano::projective::DeformationInfo info;
  for (auto _ : state) {
    const auto result = plano::projective::deform(*backend, fine, yas.constraints, settings);
    info = result.info;
    benchmark::DoNotOptimize(result.mesh.vertices.data());
  }
  state.counters["iterations"] = info.iterations;
  state.counters["max_planarity_pct"] = info.planarity.max;
  state.counters["constraint_error"] = info.maxConstraintError;
}

BENCHMARK(BM_MultiresDeform)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_DirectDeform)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
