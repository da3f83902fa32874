#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

class DeformCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir / "grid.obj", generate::translationalSurface(6, 6));
    // Fixed row v = 0 (vertices 0, 7, ..., 42) and the opposite corner 48 lifted.
    write("c.json", R"({"fixed": [0, 7, 14, 21, 28, 35, 42],
                        "handles": [{"vertex": 48, "position": [1.1, 1.1, 0.4]}]})");
  }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; }
  std::string path(const std::string& name) const { return (dir / name).string(); }
  test::TempDir dir;
};

TEST_F(DeformCommand, WritesTheMeshAndAReportWithTheSchedule) {
  const auto r = test::runTool("deform " + path("grid.obj") + " --constraints " + path("c.json") + " -o " +
                               path("out.obj") + " --report " + path("r.json"));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("iteration 1"), std::string::npos) << r.err;
  const PolygonMesh out = readMesh(dir / "out.obj");
  EXPECT_NEAR(out.vertices(48, 2), 0.4, 1e-6);
  std::ifstream in(dir / "r.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["command"], "deform");
  EXPECT_EQ(report["status"], "converged");
  EXPECT_GT(report["iterations"].get<int>(), 1);
  EXPECT_EQ(report["epsilon"].size(), report["iterations"].get<std::size_t>());
  EXPECT_EQ(report["residuals"].size(), report["iterations"].get<std::size_t>());
  EXPECT_LT(report["planarity"]["max"].get<double>(), 0.1);
  for (const char* key : {"backend", "vertices", "faces", "seconds"}) EXPECT_TRUE(report.contains(key)) << key;
  // Every step exact (ε = 0), solved directly on the CPU: no ADMM, and the progress says so.
  for (const auto& step : report["history"]) {
    EXPECT_EQ(step["epsilon_attempts"].back()["method"], "equality");
    EXPECT_EQ(step["admm_iterations"], 0);
    EXPECT_EQ(step["linear_iterations"], 0);
    EXPECT_GT(step["polish_refinements"].get<int>(), 0) << "the direct solve's method of multipliers";
  }
  EXPECT_NE(r.err.find("solved directly"), std::string::npos) << r.err;
}

TEST_F(DeformCommand, BadConstraintFilesExitWithThree) {
  write("twice.json", R"({"fixed": [3], "handles": [{"vertex": 3, "position": [0, 0, 1]}]})");
  write("range.json", R"({"fixed": [49]})");
  write("nan.json", R"({"handles": [{"vertex": 3, "position": [0, "x", 1]}]})");
  write("broken.json", R"({"fixed": [1, )");
  write("empty.json", R"({})");  // no constraint at all: most likely the wrong file (as with --space)
  for (const char* name : {"twice.json", "range.json", "nan.json", "broken.json", "empty.json"}) {
    const auto r = test::runTool("deform " + path("grid.obj") + " --constraints " + path(name) + " -o " + path("o.obj"));
    EXPECT_EQ(r.exitCode, 3) << name << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "o.obj")) << name;
  }
}

TEST_F(DeformCommand, RefusesToOverwriteTheInputUnlessInPlace) {
  const std::string args = "deform " + path("grid.obj") + " --constraints " + path("c.json") + " -o " + path("grid.obj");
  EXPECT_EQ(test::runTool(args).exitCode, 2);
  EXPECT_EQ(test::runTool(args + " --in-place").exitCode, 0);
  EXPECT_NEAR(readMesh(dir / "grid.obj").vertices(48, 2), 0.4, 1e-6);
}

TEST_F(DeformCommand, HandlesPullingAgainstEachOtherAreNamedWhenTheProjectionMovesFar) {
  // A 10x10 translational grid whose first row is fixed and whose last row is asked to bend
  // against its profile: every rigid step is infeasible at eps = 0, and the planar faces the
  // projection phase then finds lie several diagonals away.
  writeMesh(dir / "g10.obj", generate::translationalSurface(10, 10));
  write("pull.json", R"({"fixed": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10],
                         "handles": [{"vertex": 110, "position": [1.0, 0.0, 0.5]},
                                     {"vertex": 115, "position": [1.0, 0.5, -0.26]},
                                     {"vertex": 120, "position": [1.0, 1.0, 0.5]}]})");
  const auto r = test::runTool("deform " + path("g10.obj") + " --constraints " + path("pull.json") + " -o " +
                               path("out.obj") + " --max-iterations 5 -q");
  EXPECT_EQ(r.exitCode, 4) << r.err;
  EXPECT_NE(r.err.find("the projection to planar faces then moved a vertex by"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("handles that pull against each other"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.obj"));
}

TEST_F(DeformCommand, IterationCapExitsWithFourAndWritesOnlyWithKeepPartial) {
  const std::string args = "deform " + path("grid.obj") + " --constraints " + path("c.json") + " --max-iterations 1";
  const auto failed = test::runTool(args + " -o " + path("a.obj") + " --report " + path("a.json"));
  EXPECT_EQ(failed.exitCode, 4) << failed.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.obj"));
  EXPECT_TRUE(std::filesystem::exists(dir / "a.json"));
  const auto kept = test::runTool(args + " -o " + path("b.obj") + " --keep-partial");
  EXPECT_EQ(kept.exitCode, 4);
  EXPECT_TRUE(std::filesystem::exists(dir / "b.obj"));
}

}  // namespace
}  // namespace plano
