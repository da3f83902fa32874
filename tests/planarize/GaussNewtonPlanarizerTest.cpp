#include "planarize/GaussNewtonPlanarizer.h"

#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "planarize/PlanarizeTestMeshes.h"
#include "support/TestMeshes.h"

namespace plano::planarize {
namespace {

Info runGaussNewton(const PolygonMesh& mesh, Positions& result, const Settings& settings) {
  compute::CpuBackend backend;
  result = mesh.vertices;
  return GaussNewtonPlanarizer(mesh.faces, mesh.vertices, settings, backend).solve(result);
}

TEST(GaussNewtonPlanarizer, PlanarizesHyparGridWithinThirtyIterations) {
  const PolygonMesh mesh = generate::hyparGrid(8, 0.5);
  ASSERT_GT(planarityStats(mesh).max, 1.0);
  Positions result;
  const Info info = runGaussNewton(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(info.iterations, 30);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
  // The solver measures its normalized copy, the check the result in the caller's units:
  // equal up to the rounding of the normalization.
  const double measured = test::maxPlanarity(mesh.faces, result);
  EXPECT_NEAR(info.maxPlanarity.back(), measured, 1e-12 * measured);
  EXPECT_EQ(info.maxPlanarity.size(), static_cast<std::size_t>(info.iterations) + 1);
}

TEST(GaussNewtonPlanarizer, PlanarizesPerturbedTranslationalSurface) {
  PolygonMesh mesh = generate::translationalSurface(12, 10);
  mesh.vertices = test::perturbed(mesh.vertices, 0.01);
  ASSERT_GT(planarityStats(mesh).max, 2.0);
  Positions result;
  const Info info = runGaussNewton(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(info.iterations, 30);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
  // Noise of 1 % of the grid spacing needs only small corrections.
  EXPECT_LT(info.maxDisplacement, 0.02);
  EXPECT_GT(info.meanDisplacement, 0.0);
}

TEST(GaussNewtonPlanarizer, PlanarizesMixedDegreeMeshAndIgnoresTriangles) {
  const PolygonMesh mesh = test::mixedDegreeHyparPatch();
  ASSERT_GT(planarityStats(mesh).max, 1.0);
  Positions result;
  const Info info = runGaussNewton(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    EXPECT_LE(facePlanarity(result, mesh.faces[f]).mean, 0.1) << "face " << f;
  }
}

TEST(GaussNewtonPlanarizer, PlanarizesClosedMesh) {
  PolygonMesh mesh = generate::dodecahedron();
  mesh.vertices = test::perturbed(mesh.vertices, 0.05);
  ASSERT_GT(planarityStats(mesh).max, 1.0);
  Positions result;
  const Info info = runGaussNewton(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
}

TEST(GaussNewtonPlanarizer, FixedVerticesStayExactlyFixed) {
  const PolygonMesh mesh = generate::hyparGrid(6, 0.5);
  Settings settings;
  // Vertices of the first grid row, one of the second and one in the far corner.
  settings.fixed = {0, 1, 2, 3, 6, 48};
  Positions result;
  const Info info = runGaussNewton(mesh, result, settings);
  EXPECT_EQ(info.status, Status::Converged);
  for (Index v : settings.fixed) EXPECT_EQ(result.row(v), mesh.vertices.row(v)) << "vertex " << v;
  EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.1);
}

TEST(GaussNewtonPlanarizer, LargerClosenessMovesTheMeshLessAndStillReachesTheTolerance) {
  PolygonMesh mesh = generate::translationalSurface(8, 8);
  mesh.vertices = test::perturbed(mesh.vertices, 0.02);
  Settings settings;
  settings.tolerance = 0.01;
  double previousDisplacement = std::numeric_limits<double>::infinity();
  for (const double closeness : {0.0, 1e-5, 1e-3}) {
    settings.closeness = closeness;
    Positions result;
    const Info info = runGaussNewton(mesh, result, settings);
    EXPECT_EQ(info.status, Status::Converged) << "closeness " << closeness;
    EXPECT_LE(test::maxPlanarity(mesh.faces, result), 0.01) << "closeness " << closeness;
    EXPECT_LT(info.meanDisplacement, previousDisplacement) << "closeness " << closeness;
    previousDisplacement = info.meanDisplacement;
  }
}

TEST(GaussNewtonPlanarizer, ResultScalesWithTheInput) {
  const PolygonMesh mesh = generate::hyparGrid(5, 0.5);
  PolygonMesh scaled = mesh;
  scaled.vertices *= 1e4;
  Positions a, b;
  const Info infoA = runGaussNewton(mesh, a, Settings{});
  const Info infoB = runGaussNewton(scaled, b, Settings{});
  EXPECT_EQ(infoA.iterations, infoB.iterations);
  EXPECT_LT(test::maxAbsDifference(a * 1e4, b), 1e-6 * 1e4);
  EXPECT_NEAR(infoA.maxDisplacement, infoB.maxDisplacement, 1e-9);
}

TEST(GaussNewtonPlanarizer, AlreadyPlanarMeshIsReturnedUnchangedWithoutIterations) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(12, 6);
  Positions result;
  const Info info = runGaussNewton(mesh, result, Settings{});
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_EQ(info.iterations, 0);
  EXPECT_LT(test::maxAbsDifference(result, mesh.vertices), 1e-12);
}

TEST(GaussNewtonPlanarizer, RejectsBadInputNamingTheElement) {
  PolygonMesh mesh = generate::hyparGrid(3, 0.5);
  compute::CpuBackend backend;
  Settings settings;
  settings.fixed = {3, 99};
  try {
    GaussNewtonPlanarizer(mesh.faces, mesh.vertices, settings, backend);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("vertex 99"), std::string::npos) << e.what();
  }
  mesh.vertices(5, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    GaussNewtonPlanarizer(mesh.faces, mesh.vertices, Settings{}, backend);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("vertex 5"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plano::planarize
