#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

/// A 4 x 4 translational base, its two-level four-point subdivision by the tool, and
/// constraints on the fine mesh: the row y = 0 fixed, the far corner lifted.
class MultiresCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir_ / "base.obj", generate::translationalSurface(4, 4));
    const auto sub = test::runTool("-q subdivide " + path("base.obj") + " -o " + path("fine.obj") +
                                   " --levels 2 --scheme four-point");
    ASSERT_EQ(sub.exitCode, 0) << sub.err;
    fine_ = readMesh(dir_ / "fine.obj");
    nlohmann::json fixed = nlohmann::json::array();
    for (Index v = 0; v < fine_.vertexCount(); ++v) {
      if (fine_.vertices(v, 1) < 1e-9) fixed.push_back(v);
    }
    Index corner = 0;
    (fine_.vertices.rowwise() - Eigen::RowVector3d(1.2, 1.2, 0.0)).rowwise().squaredNorm().minCoeff(&corner);
    handle_ = corner;
    target_ = fine_.vertices.row(corner).transpose() + Eigen::Vector3d(0.0, 0.0, 0.2);
    const nlohmann::json constraints = {
        {"fixed", fixed}, {"handles", {{{"vertex", corner}, {"position", {target_.x(), target_.y(), target_.z()}}}}}};
    std::ofstream(dir_ / "c.json") << constraints.dump();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  test::TempDir dir_;
  PolygonMesh fine_;
  Index handle_ = 0;
  Eigen::Vector3d target_;
};

TEST_F(MultiresCommand, DeformsOnTheCoarseLevelAndReportsTheTimes) {
  const auto result = test::runTool("-q deform " + path("fine.obj") + " --constraints " + path("c.json") +
                                    " --multires --base " + path("base.obj") + " --scheme four-point -o " +
                                    path("out.obj") + " --planarity-tolerance 1 --report " + path("r.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh out = readMesh(dir_ / "out.obj");
  ASSERT_EQ(out.faces, fine_.faces);
  EXPECT_LT((out.vertices.row(handle_).transpose() - target_).norm(), 1e-6);
  EXPECT_LT(planarityStats(out).max, 1.0);
  std::ifstream in(dir_ / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["method"], "multires");
  EXPECT_EQ(report["level"], 0);
  EXPECT_EQ(report["levels"], 2);
  EXPECT_EQ(report["coarse_faces"], 16);
  EXPECT_EQ(report["fine_faces"], 256);
  EXPECT_DOUBLE_EQ(report["smoothness"].get<double>(), 3.5);
  EXPECT_EQ(report["level_checks"].size(), 3u);
  for (const char* key : {"coarse_deform", "prolongation", "deform", "hierarchy"}) {
    EXPECT_GE(report["times"][key].get<double>(), 0.0) << key;
  }
}

TEST_F(MultiresCommand, NeedsTheBaseMeshOfTheHierarchy) {
  const std::string common = "deform " + path("fine.obj") + " --constraints " + path("c.json") + " -o " + path("o.obj");
  EXPECT_EQ(test::runTool(common + " --multires").exitCode, 2);
  writeMesh(dir_ / "other.obj", generate::translationalSurface(3, 5));
  const auto wrong = test::runTool(common + " --multires --base " + path("other.obj"));
  EXPECT_EQ(wrong.exitCode, 3) << wrong.err;
  EXPECT_NE(wrong.err.find("not a subdivision"), std::string::npos) << wrong.err;
}

}  // namespace
}  // namespace plano
