// plano info: counts, topology and validation in the JSON report, exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

nlohmann::json infoJson(const std::filesystem::path& mesh, test::ToolResult* result = nullptr) {
  const auto r = test::runTool("info --json " + mesh.string());
  if (result) *result = r;
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(InfoCommand, ReportsTopologyOfAClosedMesh) {
  const test::TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const auto j = infoJson(dir / "cube.obj");
  EXPECT_EQ(j["command"], "info");
  EXPECT_EQ(j["vertices"], 8);
  EXPECT_EQ(j["edges"], 12);
  EXPECT_EQ(j["faces"], 6);
  EXPECT_EQ(j["boundaries"], 0);
  EXPECT_EQ(j["boundary_vertices"], 0);
  EXPECT_EQ(j["euler_characteristic"], 2);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["validation"]["status"], "valid");
  EXPECT_TRUE(j["validation"]["errors"].empty());
  EXPECT_TRUE(j["validation"]["warnings"].empty());
  for (const char* key : {"max", "mean", "p95", "over_tolerance"}) EXPECT_TRUE(j["planarity"].contains(key)) << key;
}

TEST(InfoCommand, ReportsBoundariesOfACylinder) {
  const test::TempDir dir;
  writeMesh(dir / "cylinder.ply", generate::surfaceOfRevolution(10, 3));
  const auto j = infoJson(dir / "cylinder.ply");
  EXPECT_EQ(j["boundaries"], 2);
  EXPECT_EQ(j["boundary_vertices"], 20);
  EXPECT_EQ(j["euler_characteristic"], 0);
  EXPECT_EQ(j["genus"], 0);
}

TEST(InfoCommand, WarningsGoToStderrAndKeepExitCodeZero) {
  test::ToolResult result;
  const auto j = infoJson(std::filesystem::path(PLANO_TEST_DATA_DIR) / "good" / "obj_isolated_vertex.obj", &result);
  EXPECT_NE(result.err.find("warning"), std::string::npos);
  EXPECT_NE(result.err.find("vertex 6 is isolated"), std::string::npos) << result.err;
  EXPECT_EQ(j["validation"]["status"], "valid_with_warnings");
  ASSERT_EQ(j["validation"]["warnings"].size(), 1u);
  EXPECT_EQ(j["validation"]["warnings"][0]["kind"], "isolated_vertex");
  EXPECT_EQ(j["validation"]["warnings"][0]["vertex"], 6);
  EXPECT_EQ(j["isolated_vertices"], 1);
}

TEST(InfoCommand, InvalidMeshExitsWithCode3AndListsTheErrors) {
  const test::TempDir dir;
  // Two triangles sharing edge (0, 1) in the same direction, and a face repeating a vertex.
  std::ofstream(dir / "bad.off") << "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n1 1 1\n3 0 1 2\n3 0 1 3\n3 2 4 2\n";
  const auto result = test::runTool("info " + (dir / "bad.off").string());
  EXPECT_EQ(result.exitCode, 3);
  EXPECT_NE(result.err.find("face 2 repeats vertex 2"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("inconsistent orientation"), std::string::npos) << result.err;
}

TEST(InfoCommand, ReportFileMatchesJsonOutput) {
  const test::TempDir dir;
  writeMesh(dir / "dome.off", generate::hexagonalDome(2));
  const auto result = test::runTool("info --json " + (dir / "dome.off").string() + " --report " +
                                    (dir / "report.json").string());
  ASSERT_EQ(result.exitCode, 0) << result.err;
  std::ifstream in(dir / "report.json");
  auto stdoutJson = nlohmann::json::parse(result.out);
  auto fileJson = nlohmann::json::parse(in);
  EXPECT_EQ(fileJson["edges"], stdoutJson["edges"]);
  EXPECT_EQ(fileJson["validation"], stdoutJson["validation"]);
}

TEST(InfoCommand, GenusOfSharedDoubleTorusIsTwo) {
  PLANO_REQUIRE_SHARED_MESH(path, "double_torus_quads.off");
  const auto j = infoJson(path);
  EXPECT_EQ(j["genus"], 2);
  EXPECT_EQ(j["euler_characteristic"], -2);
}

TEST(InfoCommand, MissingFileIsBadInput) {
  const auto result = test::runTool("info /nonexistent/mesh.obj");
  EXPECT_EQ(result.exitCode, 3);
  EXPECT_NE(result.err.find("no such file"), std::string::npos) << result.err;
}

TEST(InfoCommand, UnknownExtensionIsUsageError) {
  const auto result = test::runTool("info mesh.stl");
  EXPECT_EQ(result.exitCode, 2);
}

}  // namespace
}  // namespace plano
