#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

class PrescribeInterpolateCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = generate::translationalSurface(6, 6);
    writeMesh(dir / "grid.obj", mesh);
    std::ofstream(dir / "fixed.json") << R"({"fixed": [0, 1, 2, 3, 4, 5, 6]})";
  }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  nlohmann::json report(const std::string& name) const {
    std::ifstream in(dir / name);
    return nlohmann::json::parse(in);
  }
  test::TempDir dir;
  PolygonMesh mesh;
};

TEST_F(PrescribeInterpolateCommands, PrescribeEachMapKindKeepsFixedVerticesAndPlanarity) {
  for (const std::string map : {"rotate --angle 20 --axis 1 0 0 --pivot face", "warp --strength 0.4 --axis 0 1 0",
                                "scale --t 0.5"}) {
    const auto r = test::runTool("prescribe " + path("grid.obj") + " --map " + map + " --constraints " +
                                 path("fixed.json") + " -o " + path("p.obj") + " --report " + path("p.json"));
    ASSERT_EQ(r.exitCode, 0) << map << ": " << r.err;
    const PolygonMesh out = readMesh(dir / "p.obj");
    for (Index v = 0; v <= 6; ++v) EXPECT_LT((out.vertices.row(v) - mesh.vertices.row(v)).norm(), 1e-6) << map;
    EXPECT_GT(test::maxAbsDifference(out.vertices, mesh.vertices), 1e-3) << map;
    const auto j = report("p.json");
    EXPECT_EQ(j["command"], "prescribe");
    EXPECT_LT(j["planarity"]["max"].get<double>(), 0.1) << map;
    EXPECT_FALSE(j["epsilon"].empty());
  }
}

TEST_F(PrescribeInterpolateCommands, PrescribeRejectsUnknownMapsAndFaces) {
  EXPECT_EQ(test::runTool("prescribe " + path("grid.obj") + " --map twist -o " + path("x.obj")).exitCode, 2);
  EXPECT_EQ(test::runTool("prescribe " + path("grid.obj") + " --map rotate --faces 1,99 -o " + path("x.obj")).exitCode, 2);
}

TEST_F(PrescribeInterpolateCommands, InterpolateReturnsTheEndpointsAndPlanarMeshesBetween) {
  ASSERT_EQ(test::runTool("prescribe " + path("grid.obj") + " --map rotate --angle 40 --axis 0 1 0 --pivot face "
                          "--constraints " + path("fixed.json") + " -o " + path("b.obj")).exitCode, 0);
  const PolygonMesh b = readMesh(dir / "b.obj");
  for (double t : {0.0, 0.5, 1.0, 1.5}) {
    const auto r = test::runTool("interpolate " + path("grid.obj") + " " + path("b.obj") + " --t " + std::to_string(t) +
                                 " -o " + path("i.obj") + " --report " + path("i.json"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const PolygonMesh out = readMesh(dir / "i.obj");
    if (t == 0.0) {
      EXPECT_LT(test::maxAbsDifference(out.vertices, mesh.vertices), 1e-6);
    }
    if (t == 1.0) {
      EXPECT_LT(test::maxAbsDifference(out.vertices, b.vertices), 1e-6);
    }
    const auto j = report("i.json");
    EXPECT_LT(j["planarity"]["max"].get<double>(), 1e-3) << "t = " << t;
    ASSERT_FALSE(j["epsilon_attempts"].empty()) << "t = " << t;
    for (const auto& attempt : j["epsilon_attempts"]) EXPECT_TRUE(attempt.contains("method")) << "t = " << t;
  }
  EXPECT_EQ(test::runTool("interpolate " + path("grid.obj") + " missing.obj --t 0.5 -o " + path("i.obj")).exitCode, 3);
}

}  // namespace
}  // namespace plano
