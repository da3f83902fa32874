// Valid files with the oddities real-world meshes have (wrapped lines, CRLF, texture
// indices, colours, relative indices, both byte orders, ...) load exactly.
#include <gtest/gtest.h>

#include <set>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

std::filesystem::path goodDir() { return std::filesystem::path(PLANO_TEST_DATA_DIR) / "good"; }

/// The mesh most good files hold: two unit quads side by side.
PolygonMesh twoQuads() {
  PolygonMesh mesh;
  mesh.vertices.resize(6, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0;
  mesh.faces = FaceList({{0, 1, 4, 3}, {1, 2, 5, 4}});
  return mesh;
}

class TwoQuadFiles : public ::testing::TestWithParam<const char*> {};

TEST_P(TwoQuadFiles, LoadExactly) {
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warnings = &warnings;
  const PolygonMesh mesh = readMesh(goodDir() / GetParam(), options);
  const PolygonMesh expected = twoQuads();
  EXPECT_EQ(mesh.vertices, expected.vertices);
  EXPECT_EQ(mesh.faces, expected.faces);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

INSTANTIATE_TEST_SUITE_P(Files, TwoQuadFiles,
                         ::testing::Values("off_wrapped_face_lines.off", "off_counts_on_header_line.off",
                                           "off_colours_and_comments.off", "off_crlf.off",
                                           "obj_texture_normal_indices.obj", "obj_relative_indices.obj",
                                           "obj_crlf.obj", "obj_line_continuation.obj", "obj_very_long_line.obj",
                                           "obj_vertex_colours.obj", "ply_binary_big_endian.ply",
                                           "ply_binary_little_endian_crlf_header.ply"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(GoodInputCorpus, IsolatedVertexLoadsWithAWarning) {
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warnings = &warnings;
  const PolygonMesh mesh = readMesh(goodDir() / "obj_isolated_vertex.obj", options);
  EXPECT_EQ(mesh.vertexCount(), 7);
  EXPECT_EQ(mesh.faceCount(), 2);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("vertex 6 is isolated (in no face)"), std::string::npos) << warnings[0];
}

TEST(GoodInputCorpus, StraightRunInHexagonLoadsWithAWarning) {
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warnings = &warnings;
  const PolygonMesh mesh = readMesh(goodDir() / "hexagon_with_straight_run.off", options);
  EXPECT_EQ(mesh.faces.degree(0), 6);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("are collinear"), std::string::npos);
}

TEST(GoodInputCorpus, PlyWithExtraPropertiesAndElementsKeepsPolygons) {
  const PolygonMesh mesh = readMesh(goodDir() / "ply_ascii_mixed_polygons.ply");
  ASSERT_EQ(mesh.vertexCount(), 6);
  EXPECT_EQ(mesh.vertices(4, 1), 1.5);
  EXPECT_EQ(mesh.faces, FaceList({{1, 2, 3}, {0, 1, 3, 4, 5}}));
}

TEST(GoodInputCorpus, InfoCommandAcceptsEveryGoodFile) {
  std::set<std::string> warned = {"obj_isolated_vertex.obj", "hexagon_with_straight_run.off"};
  for (const auto& entry : std::filesystem::directory_iterator(goodDir())) {
    const auto result = test::runTool("info " + entry.path().string());
    EXPECT_EQ(result.exitCode, 0) << entry.path() << ": " << result.err;
    const bool expectWarning = warned.count(entry.path().filename()) > 0;
    EXPECT_EQ(result.err.find("warning") != std::string::npos, expectWarning) << entry.path() << ": " << result.err;
  }
}

TEST(GoodInputCorpus, NonFiniteValueOfAnUnusedPlyPropertyIsAccepted) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float quality\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 nan\n1 0 0 inf\n0 1 0 1\n3 0 1 2\n";
  EXPECT_EQ(parseMesh(ply, MeshFormat::Ply, "q.ply").vertexCount(), 3);
  std::string bad = ply;
  bad.replace(bad.find("1 0 0 inf"), 9, "1 nan 0 0");
  try {
    parseMesh(bad, MeshFormat::Ply, "q.ply");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("q.ply:12: vertex 1: coordinate y is not finite"), std::string::npos)
        << e.what();
  }
}

TEST(GoodInputCorpus, PlyElementWithoutPropertiesAndHugeCountIsSkippedAtOnce) {
  // Regression (fuzzing): an element of no properties and a count of billions hung the reader.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement marker 4000000000\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(parseMesh(ply, MeshFormat::Ply, "marker.ply").faceCount(), 1);
}

TEST(GoodInputCorpus, UnknownObjStatementIsSkippedWithAWarning) {
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warnings = &warnings;
  const PolygonMesh mesh =
      parseMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nfrobnicate 1 2\nf 1 2 3\n", MeshFormat::Obj, "m.obj", options);
  EXPECT_EQ(mesh.faceCount(), 1);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "m.obj:4: unknown statement 'frobnicate' ignored");
}

TEST(GoodInputCorpus, ReadingWithoutValidationKeepsDefectiveFaces) {
  ReadOptions options;
  options.validate = false;
  const PolygonMesh mesh =
      readMesh(std::filesystem::path(PLANO_TEST_DATA_DIR) / "bad" / "off_non_manifold_edge.off", options);
  EXPECT_EQ(mesh.faceCount(), 3);  // none dropped, unlike a half-edge reader
}

}  // namespace
}  // namespace plano
