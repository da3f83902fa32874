// The subspace commands of the plano tool, end to end (subspace, explore, shapes, dual,
// embed, and the subspace deformation request behind `plano deform --space`).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) about the
// concatenation of literals around a temporary here.
std::string quoted(const std::filesystem::path& p) {
  std::string q(1, '"');
  q += p.string();
  q += '"';
  return q;
}

TEST(SubspaceCommand, ReportsDimensionLowerBoundAndFaceTypes) {
  TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const auto result = runTool("-q subspace " + quoted(dir / "cube.obj") + " --space parallel --report " +
                              quoted(dir / "r.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto j = readJson(dir / "r.json");
  EXPECT_EQ(j["command"], "subspace");
  EXPECT_EQ(j["dimension"], 6);
  EXPECT_EQ(j["lower_bound"], 3 * 8 - 24 + 6);
  EXPECT_DOUBLE_EQ(j["free_vertices"].get<double>(), 2.0);
  EXPECT_EQ(j["face_types"].size(), 6u);
  EXPECT_EQ(j["non_maximal_faces"].size(), 6u);
  EXPECT_TRUE(j.contains("planarity"));
  EXPECT_TRUE(j.contains("seconds"));
}

TEST(SubspaceCommand, AskedForVulkanItWarnsThatItComputesOnTheCpuAndReportsCpu) {
  // The linear-space commands have no device kernels: the result is the CPU's, and the
  // user is told so, even with -q (a warning, not progress), instead of reading CPU
  // timings as the device's.
  TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const auto asked = runTool("-q --backend vulkan subspace " + quoted(dir / "cube.obj") + " --space parallel --report " +
                             quoted(dir / "r.json"));
  ASSERT_EQ(asked.exitCode, 0) << asked.err;
  EXPECT_NE(asked.err.find("warning: plano subspace computes on the CPU"), std::string::npos) << asked.err;
  EXPECT_EQ(readJson(dir / "r.json")["backend"], "cpu");
  const auto plain = runTool("-q subspace " + quoted(dir / "cube.obj") + " --space parallel");
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  EXPECT_EQ(plain.err.find("warning"), std::string::npos) << plain.err;
}

TEST(SubspaceCommand, OnAMeshWithNonPlanarFacesItWarnsThatItsSpaceIsApproximate) {
  // Even with -q: the shapes of such a space are not polyhedral, whatever the run says.
  TempDir dir;
  writeMesh(dir / "hypar.obj", generate::hyparGrid(6));
  for (const std::string command : {"subspace", "explore"}) {
    const auto result = runTool("-q " + command + " " + quoted(dir / "hypar.obj") +
                                (command == "explore" ? " -o " + quoted(dir / "out.obj") : std::string()));
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_NE(result.err.find("warning: plano " + command + ": the mesh's faces are not planar"), std::string::npos)
        << result.err;
    EXPECT_NE(result.err.find("plano planarize"), std::string::npos) << result.err;
  }
}

TEST(SubspaceCommand, MixedSpaceReadsTheFacesFileAndRejectsAShortOne) {
  TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  { std::ofstream(dir / "faces.txt") << "affine parallel vertical\n# comment\na p v\n"; }
  const auto ok = runTool("-q subspace " + quoted(dir / "cube.obj") + " --space mixed --faces-file " +
                          quoted(dir / "faces.txt") + " --report " + quoted(dir / "r.json"));
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_EQ(readJson(dir / "r.json")["face_types"][0], "affine");
  { std::ofstream(dir / "short.txt") << "affine parallel\n"; }
  const auto bad = runTool("-q subspace " + quoted(dir / "cube.obj") + " --space mixed --faces-file " +
                           quoted(dir / "short.txt"));
  EXPECT_EQ(bad.exitCode, 3);
  EXPECT_NE(bad.err.find("2 face spaces"), std::string::npos) << bad.err;
}

TEST(ExploreCommand, WritesAPolyhedralMeshWithTheBandAdded) {
  TempDir dir;
  writeMesh(dir / "dome.obj", generate::hexagonalDome(2));
  const auto result = runTool("-q explore " + quoted(dir / "dome.obj") +
                              " --space vertical --eigenshapes 8 --band 3:6 --amplitude 0.05 -o " +
                              quoted(dir / "out.obj") + " --report " + quoted(dir / "r.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh out = readMesh(dir / "out.obj");
  const PolygonMesh in = readMesh(dir / "dome.obj");
  EXPECT_GT((out.vertices - in.vertices).norm(), 1e-3);
  // Single-precision OBJ output bounds what the file can show.
  EXPECT_LE(planarityStats(out).max, 1e-3);
  EXPECT_EQ(readJson(dir / "r.json")["frequencies"].size(), 8u);
}

TEST(ShapesCommand, SparseAndFundamentalShapesRun) {
  TempDir dir;
  writeMesh(dir / "rev.obj", generate::surfaceOfRevolution(12, 6));
  for (const char* kind : {"sparse", "fundamental"}) {
    const auto result = runTool(std::string("-q shapes ") + quoted(dir / "rev.obj") + " --space affine --kind " + kind +
                                " --vertex 41 --direction 0,0,1 -o " + quoted(dir / "out.obj") + " --report " +
                                quoted(dir / "r.json"));
    ASSERT_EQ(result.exitCode, 0) << kind << ": " << result.err;
    EXPECT_EQ(readJson(dir / "r.json")["kind"], kind);
  }
  EXPECT_EQ(readJson(dir / "r.json")["shape"]["dimension"].get<int>() > 0, true);
  const auto bad = runTool("-q shapes " + quoted(dir / "rev.obj") + " --vertex 100000 -o " + quoted(dir / "x.obj"));
  EXPECT_EQ(bad.exitCode, 2);
}

TEST(DualCommand, WritesTheDualAndAnExploredPrimal) {
  TempDir dir;
  PolygonMesh dodecahedron = generate::dodecahedron();
  writeMesh(dir / "d.obj", dodecahedron);
  const auto result = runTool("-q dual " + quoted(dir / "d.obj") + " -o " + quoted(dir / "dual.obj") + " --primal " +
                              quoted(dir / "primal.obj") + " --space affine --eigenshape 12 --report " +
                              quoted(dir / "r.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const PolygonMesh dual = readMesh(dir / "dual.obj");
  EXPECT_EQ(dual.vertexCount(), 12);
  EXPECT_EQ(dual.faceCount(), 20);
  const PolygonMesh primal = readMesh(dir / "primal.obj");
  EXPECT_LE(planarityStats(primal).max, 1e-3);
}

TEST(DualCommand, TheUpVectorChoosesTheDualsVerticalSpace) {
  // The cube's dual, an octahedron, has more vertical meshes for up = z, an axis of its
  // symmetry, than for a generic up vector.
  TempDir dir;
  writeMesh(dir / "cube.obj", generate::cube());
  const auto dimensionFor = [&](const std::string& up) {
    const auto result = runTool("-q dual " + quoted(dir / "cube.obj") + " -o " + quoted(dir / "dual.obj") +
                                " --primal " + quoted(dir / "primal.obj") + " --space vertical --eigenshape 0" + up +
                                " --report " + quoted(dir / "r.json"));
    EXPECT_EQ(result.exitCode, 0) << result.err;
    return result.exitCode == 0 ? readJson(dir / "r.json")["exploration"]["dimension"].get<int>() : -1;
  };
  const int alongZ = dimensionFor("");
  EXPECT_EQ(dimensionFor(" --up 0,0,2"), alongZ);
  EXPECT_LT(dimensionFor(" --up 0.3,0.1,1"), alongZ);
}

TEST(EmbedCommand, LiftsATutteEmbeddingOfADisk) {
  TempDir dir;
  writeMesh(dir / "grid.obj", generate::hyparGrid(6));
  const auto result = runTool("-q embed " + quoted(dir / "grid.obj") + " -o " + quoted(dir / "out.obj") +
                              " --report " + quoted(dir / "r.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto j = readJson(dir / "r.json");
  EXPECT_EQ(j["flipped_faces"], 0);
  EXPECT_GT(j["max_height"].get<double>(), 0.0);
  EXPECT_LE(planarityStats(readMesh(dir / "out.obj")).max, 1e-3);
  writeMesh(dir / "cube.obj", generate::cube());
  EXPECT_EQ(runTool("-q embed " + quoted(dir / "cube.obj") + " -o " + quoted(dir / "x.obj")).exitCode, 3);
}

TEST(SubspaceDeform, DeformsInsideTheSpaceAndReportsIterations) {
  TempDir dir;
  writeMesh(dir / "dome.obj", generate::hexagonalDome(2));
  {
    std::ofstream(dir / "c.json") << R"({"fixed": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9],
                                        "handles": [{"vertex": 40, "position": [0.0, 0.0, 1.2]}]})";
  }
  const auto result = runTool("-q deform " + quoted(dir / "dome.obj") + " --space vertical --constraints " +
                              quoted(dir / "c.json") + " -o " + quoted(dir / "out.obj") + " --report " +
                              quoted(dir / "r.json") + " --max-iterations 60");
  ASSERT_EQ(result.exitCode, 0) << result.err;
  const auto j = readJson(dir / "r.json");
  EXPECT_EQ(j["command"], "deform");
  // Not a stop after the first global step: the start (the rest shape, energy 0) is no
  // reference for the energy's decrease.
  EXPECT_GT(j["iterations"].get<int>(), 2);
  // Every iterate lies in null(B): the residual is at rounding level (OBJ round trips are exact).
  EXPECT_LE(j["max_subspace_residual"].get<double>(), 1e-8);
  const auto bad = runTool("-q deform " + quoted(dir / "dome.obj") + " --space affine --constraints " +
                           quoted(dir / "missing.json") + " -o " + quoted(dir / "x.obj"));
  EXPECT_EQ(bad.exitCode, 3);
}

TEST(SubspaceDeform, TheUpVectorChoosesTheVerticalSpaceAndNeedsASpace) {
  // --up is the vertical direction of `deform --space vertical` as of the other linear-space
  // commands: the flat 6x6 grid in z = 0 has more vertical meshes for up = y than for up = z,
  // where every face is horizontal. Without --space it chooses nothing and is refused.
  TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(6, 6));
  {
    std::ofstream(dir / "c.json") << R"({"fixed": [0, 1, 2, 3, 4, 5, 6],
                                        "handles": [{"vertex": 48, "position": [6.0, 6.0, 1.0]}]})";
  }
  const std::string common = "-q deform " + quoted(dir / "grid.obj") + " --constraints " + quoted(dir / "c.json") +
                             " -o " + quoted(dir / "out.obj");
  const auto dimensionFor = [&](const std::string& up) {
    const auto result = runTool(common + " --space vertical --report " + quoted(dir / "r.json") + up);
    EXPECT_EQ(result.exitCode, 0) << result.err;
    return result.exitCode == 0 ? readJson(dir / "r.json")["dimension"].get<int>() : -1;
  };
  const int alongZ = dimensionFor("");
  EXPECT_EQ(dimensionFor(" --up 0,0,1"), alongZ);
  EXPECT_GT(dimensionFor(" --up 0,1,0"), alongZ);
  const auto withoutSpace = runTool(common + " --up 0,1,0");
  EXPECT_EQ(withoutSpace.exitCode, 2);
  EXPECT_NE(withoutSpace.err.find("need --space"), std::string::npos) << withoutSpace.err;
  EXPECT_EQ(runTool(common + " --space vertical --up 0,0,0").exitCode, 2);
}

}  // namespace
}  // namespace plano::test
