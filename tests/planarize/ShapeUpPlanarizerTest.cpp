#include "planarize/ShapeUpPlanarizer.h"

#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "planarize/AndersonPlanarizer.h"
#include "planarize/PlanarizeTestMeshes.h"
#include "support/TestMeshes.h"

namespace plano::planarize {
namespace {

PolygonMesh perturbedSurface() {
  PolygonMesh mesh = generate::translationalSurface(8, 8);
  mesh.vertices = test::perturbed(mesh.vertices, 0.01);
  return mesh;
}

TEST(ShapeUpPlanarizer, ReachesOnePercentOnPerturbedSurface) {
  const PolygonMesh mesh = perturbedSurface();
  ASSERT_GT(planarityStats(mesh).max, 2.0);
  compute::CpuBackend backend;
  Settings settings;
  settings.tolerance = 1.0;
  settings.maxIterations = 2000;
  Positions result = mesh.vertices;
  const Info info = ShapeUpPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(planarityStats(PolygonMesh{result, mesh.faces}).max, 1.0);
  EXPECT_GT(info.iterations, 0);
}

TEST(ShapeUpPlanarizer, PlanarityDecreasesEveryIterationOnMildInput) {
  const PolygonMesh mesh = perturbedSurface();
  compute::CpuBackend backend;
  Settings settings;
  settings.tolerance = 0.0;
  settings.maxIterations = 20;
  Positions result = mesh.vertices;
  const Info info = ShapeUpPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
  ASSERT_EQ(info.meanPlanarity.size(), 21u);
  for (std::size_t k = 1; k < info.meanPlanarity.size(); ++k) {
    EXPECT_LT(info.meanPlanarity[k], info.meanPlanarity[k - 1]) << "iteration " << k;
  }
}

TEST(ShapeUpPlanarizer, FixedVerticesStayExactlyFixed) {
  const PolygonMesh mesh = test::mixedDegreeHyparPatch();
  compute::CpuBackend backend;
  Settings settings;
  settings.tolerance = 0.0;
  settings.maxIterations = 50;
  settings.fixed = {0, 6, 48};
  Positions result = mesh.vertices;
  ShapeUpPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
  for (Index v : settings.fixed) EXPECT_EQ(result.row(v), mesh.vertices.row(v)) << "vertex " << v;
  EXPECT_LT(planarityStats(PolygonMesh{result, mesh.faces}).max, planarityStats(mesh).max);
}

TEST(AndersonPlanarizer, NeedsFewerIterationsThanShapeUpForTheSameTolerance) {
  const PolygonMesh mesh = perturbedSurface();
  compute::CpuBackend backend;
  Settings settings;
  settings.tolerance = 0.5;
  settings.maxIterations = 3000;
  Positions plain = mesh.vertices, accelerated = mesh.vertices;
  const Info shapeUp = ShapeUpPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(plain);
  const Info anderson = AndersonPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(accelerated);
  ASSERT_EQ(shapeUp.status, Status::Converged);
  EXPECT_EQ(anderson.status, Status::Converged);
  EXPECT_LT(anderson.iterations, shapeUp.iterations);
  EXPECT_LE(planarityStats(PolygonMesh{accelerated, mesh.faces}).max, 0.5);
}

TEST(AndersonPlanarizer, FixedVerticesStayExactlyFixed) {
  const PolygonMesh mesh = generate::hyparGrid(6, 0.5);
  compute::CpuBackend backend;
  Settings settings;
  settings.tolerance = 0.0;
  settings.maxIterations = 40;
  settings.fixed = {0, 6, 48};
  Positions result = mesh.vertices;
  const Info info = AndersonPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
  for (Index v : settings.fixed) EXPECT_EQ(result.row(v), mesh.vertices.row(v)) << "vertex " << v;
  EXPECT_LT(info.maxPlanarity.back(), info.maxPlanarity.front());
}

}  // namespace
}  // namespace plano::planarize
