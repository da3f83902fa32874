#include "planarize/GuidedProjectionPlanarizer.h"

#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "planarize/PlanarizeTestMeshes.h"
#include "support/TestMeshes.h"

namespace plano::planarize {
namespace {

Info runGuidedProjection(const PolygonMesh& mesh, Positions& result, const Settings& settings) {
  compute::CpuBackend backend;
  result = mesh.vertices;
  return GuidedProjectionPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
}

TEST(GuidedProjectionPlanarizer, PlanarizesHyparGridWithinThirtyIterations) {
  const PolygonMesh mesh = generate::hyparGrid(8, 0.5);
  ASSERT_GT(planarityStats(mesh).max, 1.0);
  Positions result;
  const Info info = runGuidedProjection(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(info.iterations, 30);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
  // The solver measures its normalized copy, the check the result in the caller's units:
  // equal up to the rounding of the normalization.
  const double measured = test::maxPlanarity(mesh.faces, result);
  EXPECT_NEAR(info.maxPlanarity.back(), measured, 1e-12 * measured);
  EXPECT_EQ(info.maxPlanarity.size(), static_cast<std::size_t>(info.iterations) + 1);
}

TEST(GuidedProjectionPlanarizer, PlanarizesMixedDegreeMeshAndIgnoresTriangles) {
  const PolygonMesh mesh = test::mixedDegreeHyparPatch();
  ASSERT_GT(planarityStats(mesh).max, 1.0);
  Positions result;
  const Info info = runGuidedProjection(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    EXPECT_LE(facePlanarity(result, mesh.faces[f]).mean, 0.1) << "face " << f;
  }
}

TEST(GuidedProjectionPlanarizer, FixedVerticesStayExactlyFixed) {
  const PolygonMesh mesh = generate::hyparGrid(6, 0.5);
  Settings settings;
  // Vertices of the first grid row, one of the second and one in the far corner.
  settings.fixed = {0, 1, 2, 3, 6, 48};
  Positions result;
  const Info info = runGuidedProjection(mesh, result, settings);
  EXPECT_EQ(info.status, Status::Converged);
  for (Index v : settings.fixed) EXPECT_EQ(result.row(v), mesh.vertices.row(v)) << "vertex " << v;
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
}

TEST(GuidedProjectionPlanarizer, LargerClosenessMovesTheMeshLessAndLeavesItLessPlanar) {
  PolygonMesh mesh = generate::translationalSurface(8, 8);
  mesh.vertices = test::perturbed(mesh.vertices, 0.02);
  Settings settings;
  settings.tolerance = 0.0;  // run to the fixed point of each weight
  settings.maxIterations = 30;
  double previousDisplacement = std::numeric_limits<double>::infinity();
  double previousPlanarity = -1.0;
  for (const double closeness : {1e-5, 1e-3, 1e-1, 10.0}) {
    settings.closeness = closeness;
    Positions result;
    const Info info = runGuidedProjection(mesh, result, settings);
    const double planarity = test::maxPlanarity(mesh.faces, result);
    EXPECT_LT(info.meanDisplacement, previousDisplacement) << "closeness " << closeness;
    EXPECT_GT(planarity, previousPlanarity) << "closeness " << closeness;
    previousDisplacement = info.meanDisplacement;
    previousPlanarity = planarity;
  }
}

}  // namespace
}  // namespace plano::planarize
