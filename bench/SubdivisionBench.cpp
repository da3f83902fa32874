// Subdivision: linear schemes (refinement topology + target positions) on generated
// meshes refined to ~4k, ~64k and ~1M faces.
#include <benchmark/benchmark.h>

#include "mesh/Generators.h"
#include "projective/QuadRefinement.h"
#include "projective/SubdivisionSchemes.h"

namespace {

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
