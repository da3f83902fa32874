#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

TEST(SubdivisionCommand, WritesThePlanarQuadMeshAndAReportPerLevel) {
  test::TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const auto result = test::runTool("-q subdivide " + (dir / "cube.obj").string() + " -o " + (dir / "fine.obj").string() +
                                    " --levels 2 --report " + (dir / "report.json").string());
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh fine = readMesh(dir / "fine.obj");
  EXPECT_EQ(fine.faceCount(), 96);
  EXPECT_LT(planarityStats(fine).max, 0.1);
  std::ifstream in(dir / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["command"], "subdivide");
  EXPECT_EQ(report["scheme"], "catmull-clark");
  EXPECT_EQ(report["status"], "converged");
  EXPECT_EQ(report["faces"], 96);
  ASSERT_EQ(report["levels"].size(), 2u);
  int iterations = 0;
  for (const auto& level : report["levels"]) {
    EXPECT_EQ(level["epsilons"].size(), level["iterations"].get<std::size_t>());
    for (const auto& step : level["steps"]) {
      // The ε schedule of each step, ending with the attempt that solved at the step's ε.
      const auto& attempts = step["epsilon_attempts"];
      ASSERT_FALSE(attempts.empty());
      const std::string status = attempts.back()["status"];
      EXPECT_TRUE(status == "solved" || status == "solved_inaccurate") << status;
      EXPECT_EQ(attempts.back()["method"], "admm");  // relaxed attempts (l < u) take the ADMM
      EXPECT_EQ(attempts.back()["epsilon"].get<double>(), step["epsilon"].get<double>());
      int admm = 0;
      for (const auto& attempt : attempts) admm += attempt["iterations"].get<int>();
      EXPECT_EQ(admm, step["admm_iterations"].get<int>());
    }
    EXPECT_LT(level["planarity"]["max"].get<double>(), 0.1);
    iterations += level["iterations"].get<int>();
  }
  EXPECT_EQ(report["iterations"], iterations);
}

TEST(SubdivisionCommand, PrintsAProgressLinePerIterationUnlessQuiet) {
  test::TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const std::string args = "subdivide " + (dir / "cube.obj").string() + " -o " + (dir / "fine.obj").string() +
                           " --levels 2 --report " + (dir / "report.json").string();
  const auto loud = test::runTool(args);
  ASSERT_EQ(loud.exitCode, 0) << loud.err;
  std::ifstream in(dir / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  for (const auto& level : report["levels"]) {
    const int n = level["iterations"].get<int>();
    ASSERT_GE(n, 1);
    for (int i = 1; i <= n; ++i) {
      const std::string prefix = "level " + std::to_string(level["level"].get<int>()) + ", iteration " +
                                 std::to_string(i) + ": max planarity ";
      EXPECT_NE(loud.err.find(prefix), std::string::npos) << prefix << "\n" << loud.err;
    }
    const std::string beyond = "level " + std::to_string(level["level"].get<int>()) + ", iteration " +
                               std::to_string(n + 1) + ":";
    EXPECT_EQ(loud.err.find(beyond), std::string::npos) << loud.err;
  }
  const auto quiet = test::runTool("-q " + args);
  ASSERT_EQ(quiet.exitCode, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("iteration"), std::string::npos) << quiet.err;
}

TEST(SubdivisionCommand, ReportsAndPrintsTheSkippedAttempts) {
  // A 3-ring dome's level held to 0.005 %: its small attempts stall in two steps, and the
  // later steps skip them (GlobalStepSettings::stalledAttemptSkips).
  test::TempDir dir;
  writeMesh(dir / "dome.obj", generate::hexagonalDome(3));
  const auto result = test::runTool("subdivide " + (dir / "dome.obj").string() + " -o " + (dir / "fine.obj").string() +
                                    " --levels 1 --tolerance 0.005 --max-iterations 8 --report " +
                                    (dir / "report.json").string());
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::ifstream in(dir / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  int skipped = 0;
  for (const auto& step : report["levels"][0]["steps"]) {
    int stepSkipped = 0;
    for (const auto& attempt : step["epsilon_attempts"]) {
      if (attempt["status"] != "skipped") continue;
      ++stepSkipped;
      EXPECT_EQ(attempt["method"], "none");
      EXPECT_EQ(attempt["iterations"], 0);
    }
    EXPECT_NE(step["epsilon_attempts"].back()["status"], "skipped");
    skipped += stepSkipped;
  }
  EXPECT_GT(skipped, 0);
  EXPECT_NE(result.err.find(" skipped: stalled before)"), std::string::npos) << result.err;
}

TEST(SubdivisionCommand, InPlaceLinearFourPointKeepsTheCoarseVertices) {
  test::TempDir dir;
  const PolygonMesh cube = generate::cube();
  writeMesh(dir / "cube.off", cube);
  const auto result = test::runTool("-q subdivide " + (dir / "cube.off").string() + " --in-place --linear --scheme four-point");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh fine = readMesh(dir / "cube.off");
  EXPECT_EQ(fine.faceCount(), 24);
  EXPECT_LT(test::maxAbsDifference(fine.vertices.topRows(8), cube.vertices), 1e-15);
}

TEST(SubdivisionCommand, ReportsUsageAndInputErrorsWithTheirExitCodes) {
  test::TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const std::string mesh = (dir / "cube.obj").string();
  EXPECT_EQ(test::runTool("subdivide " + mesh).exitCode, 2);  // no output
  EXPECT_EQ(test::runTool("subdivide " + mesh + " -o x.obj --scheme loop").exitCode, 2);
  EXPECT_EQ(test::runTool("subdivide " + mesh + " -o x.obj --in-place").exitCode, 2);
  const auto missing = test::runTool("subdivide " + (dir / "missing.obj").string() + " -o " + (dir / "out.obj").string());
  EXPECT_EQ(missing.exitCode, 3) << missing.err;
  EXPECT_NE(missing.err.find("missing.obj"), std::string::npos) << missing.err;
}

TEST(SubdivisionCommand, ANonPlanarInputIsBadInputAndWritesNothing) {
  test::TempDir dir;
  writeMesh(dir / "hypar.obj", generate::hyparGrid(4, 0.5));
  const auto result =
      test::runTool("subdivide " + (dir / "hypar.obj").string() + " -o " + (dir / "fine.obj").string() + " --keep-partial");
  EXPECT_EQ(result.exitCode, 3) << result.err;
  EXPECT_NE(result.err.find("not planar enough"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "fine.obj"));
  // The linear scheme takes it.
  EXPECT_EQ(test::runTool("-q subdivide " + (dir / "hypar.obj").string() + " -o " + (dir / "fine.obj").string() +
                          " --linear").exitCode,
            0);
}

}  // namespace
}  // namespace plano
