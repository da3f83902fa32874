// The targets on the shared architectural meshes (skipped when ../shared/data is
// absent): 0.1 % max planarity within 30 iterations, displacement below the ShapeUp
// baseline's (4-6 % of the bounding-box diagonal on spot_quad).
#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "planarize/Planarize.h"
#include "support/TestMeshes.h"

namespace plano::planarize {
namespace {

Info planarizeShared(const std::filesystem::path& path, PolygonMesh& mesh) {
  mesh = readMesh(path);
  compute::CpuBackend backend;
  Settings settings;
  settings.maxIterations = 30;
  return planarize::planarize(mesh.faces, mesh.vertices, settings, backend);
}

TEST(SharedMeshPlanarize, HyparReachesTenthOfAPercentWithinThirtyIterations) {
  PLANO_REQUIRE_SHARED_MESH(path, "hypar.obj");
  PolygonMesh mesh;
  const Info info = planarizeShared(path, mesh);
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(planarityStats(mesh).max, 0.1);
}

TEST(SharedMeshPlanarize, SpotControlReachesTenthOfAPercentWithinThirtyIterations) {
  PLANO_REQUIRE_SHARED_MESH(path, "spot_control.obj");
  PolygonMesh mesh;
  const Info info = planarizeShared(path, mesh);
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(planarityStats(mesh).max, 0.1);
}

TEST(SharedMeshPlanarize, SpotQuadReachesTenthOfAPercentMovingLessThanTheBaseline) {
  PLANO_REQUIRE_SHARED_MESH(path, "spot_quad.obj");
  PolygonMesh mesh;
  const Info info = planarizeShared(path, mesh);
  EXPECT_EQ(info.status, Status::Converged);
  EXPECT_LE(planarityStats(mesh).max, 0.1);
  EXPECT_LT(info.maxDisplacement, 0.04);
}

}  // namespace
}  // namespace plano::planarize
