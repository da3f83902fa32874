// `plano planarize`: output, report, exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

TEST(PlanarizeCommand, WritesPlanarMeshAndReport) {
  test::TempDir dir;
  writeMesh(dir / "in.obj", generate::hyparGrid(6, 0.5));
  const auto result = test::runTool("planarize " + (dir / "in.obj").string() + " -o " + (dir / "out.obj").string() +
                                    " --tolerance 0.1 --report " + (dir / "r.json").string());
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_LE(planarityStats(readMesh(dir / "out.obj")).max, 0.1);
  std::ifstream in(dir / "r.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["command"], "planarize");
  EXPECT_EQ(report["status"], "converged");
  EXPECT_EQ(report["method"], "gauss-newton");
  EXPECT_LE(report["planarity"]["max"].get<double>(), 0.1);
  const int iterations = report["iterations"].get<int>();
  EXPECT_GT(iterations, 0);
  EXPECT_EQ(report["planarity_per_iteration"]["max"].size(), static_cast<std::size_t>(iterations) + 1);
  EXPECT_GT(report["displacement"]["max"].get<double>(), 0.0);
  EXPECT_TRUE(report.contains("seconds"));
}

TEST(PlanarizeCommand, UnreachedToleranceExitsWithFourAndWritesNothingUnlessKeepPartial) {
  test::TempDir dir;
  writeMesh(dir / "in.obj", generate::hyparGrid(6, 0.5));
  const std::string base = "planarize " + (dir / "in.obj").string() + " --method shapeup --max-iterations 2 -o ";
  const auto refused = test::runTool(base + (dir / "a.obj").string());
  EXPECT_EQ(refused.exitCode, 4) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.obj"));
  const auto kept = test::runTool(base + (dir / "b.obj").string() + " --keep-partial");
  EXPECT_EQ(kept.exitCode, 4) << kept.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "b.obj"));
}

TEST(PlanarizeCommand, RefusesToOverwriteTheInputUnlessInPlace) {
  test::TempDir dir;
  writeMesh(dir / "in.obj", generate::hyparGrid(4, 0.5));
  const auto refused = test::runTool("planarize " + (dir / "in.obj").string() + " -o " + (dir / "in.obj").string());
  EXPECT_EQ(refused.exitCode, 2);
  EXPECT_NE(refused.err.find("--in-place"), std::string::npos) << refused.err;
  const auto done =
      test::runTool("planarize " + (dir / "in.obj").string() + " -o " + (dir / "in.obj").string() + " --in-place");
  EXPECT_EQ(done.exitCode, 0) << done.err;
  EXPECT_LE(planarityStats(readMesh(dir / "in.obj")).max, 0.1);
}

TEST(PlanarizeCommand, KeepsFixedVerticesFromConstraintsFile) {
  test::TempDir dir;
  const PolygonMesh mesh = generate::hyparGrid(5, 0.5);
  writeMesh(dir / "in.obj", mesh);
  std::ofstream(dir / "fixed.json") << R"({"fixed": [0, 5, 30, 35]})";
  const auto result = test::runTool("planarize " + (dir / "in.obj").string() + " -o " + (dir / "out.obj").string() +
                                    " --fixed " + (dir / "fixed.json").string());
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh out = readMesh(dir / "out.obj");
  for (Index v : {0, 5, 30, 35}) EXPECT_EQ(out.vertices.row(v), mesh.vertices.row(v)) << "vertex " << v;
}

TEST(PlanarizeCommand, BadFixedVertexIsBadInput) {
  test::TempDir dir;
  writeMesh(dir / "in.obj", generate::hyparGrid(3, 0.5));
  std::ofstream(dir / "fixed.json") << R"({"fixed": [1000]})";
  const auto result = test::runTool("planarize " + (dir / "in.obj").string() + " -o " + (dir / "out.obj").string() +
                                    " --fixed " + (dir / "fixed.json").string());
  EXPECT_EQ(result.exitCode, 3) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.obj"));
}

}  // namespace
}  // namespace plano
