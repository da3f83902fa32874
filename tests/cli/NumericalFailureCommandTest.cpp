// A failed computation means the same in every computing command (tools/plano/
// CommandOutcome.h): exit code 4, the reason on stderr, "status" and "reason" in the
// report, and the output mesh written only with --keep-partial.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class NumericalFailureCommand : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// Run `arguments -o out.obj --report r.json` without and with --keep-partial and check
  /// the common failure contract; returns the report of the run without --keep-partial.
  nlohmann::json expectNumericalFailure(const std::string& arguments, const std::string& status) {
    const ToolResult refused = runTool(arguments + " -o " + path("a.obj") + " --report " + path("a.json"));
    EXPECT_EQ(refused.exitCode, 4) << refused.err;
    EXPECT_NE(refused.err.find("numerical failure"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("no output written"), std::string::npos) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "a.obj"));
    const nlohmann::json report = readReport("a.json");
    EXPECT_EQ(report.value("status", ""), status) << report.dump();
    EXPECT_FALSE(report.value("reason", "").empty()) << report.dump();
    EXPECT_EQ(report.value("output_written", true), false);

    const ToolResult kept =
        runTool(arguments + " -o " + path("b.obj") + " --report " + path("b.json") + " --keep-partial");
    EXPECT_EQ(kept.exitCode, 4) << kept.err;
    EXPECT_NE(kept.err.find("partial result written"), std::string::npos) << kept.err;
    EXPECT_NO_THROW(readMesh(dir_ / "b.obj"));
    const nlohmann::json keptReport = readReport("b.json");
    EXPECT_EQ(keptReport.value("status", ""), status);
    EXPECT_EQ(keptReport.value("output_written", false), true);
    return report;
  }

  nlohmann::json readReport(const std::string& name) const {
    std::ifstream in(dir_ / name);
    if (!in) {
      ADD_FAILURE() << "no report " << name;
      return nlohmann::json::object();
    }
    return nlohmann::json::parse(in);
  }

  TempDir dir_;
};

TEST_F(NumericalFailureCommand, DeformationAtItsIterationCap) {
  writeMesh(dir_ / "grid.obj", generate::translationalSurface(6, 6));
  std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 7, 14, 21, 28, 35, 42],
                                        "handles": [{"vertex": 48, "position": [1.1, 1.1, 0.4]}]})";
  const auto report = expectNumericalFailure(
      "deform " + path("grid.obj") + " --constraints " + path("c.json") + " --max-iterations 1", "max_iterations");
  const std::string reason = report["reason"].get<std::string>();
  EXPECT_NE(reason.find("not converged after 1 iterations"), std::string::npos) << report.dump();
  // It names the bound that was missed and its tolerance.
  EXPECT_NE(reason.find("moved a vertex by"), std::string::npos) << reason;
  EXPECT_NE(reason.find("of the diagonal (tolerance 0.0001)"), std::string::npos) << reason;
}

TEST_F(NumericalFailureCommand, PlanarizationThatCannotReachTheTolerance) {
  writeMesh(dir_ / "grid.obj", generate::hyparGrid(6, 0.5));
  const auto report = expectNumericalFailure(
      "planarize " + path("grid.obj") + " --method shapeup --max-iterations 2", "iteration_limit");
  EXPECT_NE(report["reason"].get<std::string>().find("above the tolerance"), std::string::npos) << report.dump();
}

TEST_F(NumericalFailureCommand, SubdivisionLevelAtItsIterationCap) {
  writeMesh(dir_ / "cube.obj", generate::cube());
  const auto report = expectNumericalFailure(
      "subdivide " + path("cube.obj") + " --levels 2 --max-iterations 1 --tolerance 1e-9", "iteration_limit");
  EXPECT_NE(report["reason"].get<std::string>().find("did not reach"), std::string::npos) << report.dump();
}

TEST_F(NumericalFailureCommand, SubspaceDeformationAtItsIterationCap) {
  writeMesh(dir_ / "dome.obj", generate::hexagonalDome(2));
  std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9],
                                        "handles": [{"vertex": 40, "position": [0.0, 0.0, 1.2]}]})";
  const auto report = expectNumericalFailure("-q deform " + path("dome.obj") + " --space vertical --constraints " +
                                                 path("c.json") + " --max-iterations 1",
                                             "iteration_limit");
  EXPECT_NE(report["reason"].get<std::string>().find("cap of 1 iterations"), std::string::npos) << report.dump();
}

}  // namespace
}  // namespace plano::test

namespace plano::test {
namespace {

TEST(NumericalFailureOptions, EveryComputingCommandAcceptsReportAndKeepPartial) {
  for (const char* command :
       {"deform", "planarize", "subdivide", "prescribe", "interpolate", "explore", "shapes", "dual", "embed"}) {
    const ToolResult help = runTool(std::string(command) + " --help");
    EXPECT_EQ(help.exitCode, 0) << command;
    EXPECT_NE(help.out.find("--report"), std::string::npos) << command << ":\n" << help.out;
    EXPECT_NE(help.out.find("--keep-partial"), std::string::npos) << command << ":\n" << help.out;
  }
}

}  // namespace
}  // namespace plano::test
