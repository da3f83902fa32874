// Writing and reading back gives the identical mesh in every format: every coordinate
// bit for bit, every polygon with its degree, vertex and face order unchanged.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <limits>
#include <random>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

/// Polygons of degree 3 to 9 over random vertices with awkward doubles: values that
/// need all 17 digits, tiny and huge magnitudes, negative zero, subnormals.
PolygonMesh awkwardMesh() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  PolygonMesh mesh;
  const Index vertexCount = 200;
  mesh.vertices.resize(vertexCount, 3);
  for (Index v = 0; v < vertexCount; ++v) {
    for (int a = 0; a < 3; ++a) mesh.vertices(v, a) = uniform(rng) * std::pow(10.0, static_cast<int>(rng() % 40) - 20);
  }
  mesh.vertices(0, 0) = -0.0;
  mesh.vertices(1, 1) = std::numeric_limits<double>::denorm_min();
  mesh.vertices(2, 2) = 1e99;
  mesh.vertices(3, 0) = 0.1 + 0.2;
  // Faces: runs of consecutive vertices (order and degree matter, manifoldness not).
  Index next = 0;
  for (Index degree = 3; next + degree <= vertexCount; degree = degree == 9 ? 3 : degree + 1) {
    std::vector<Index> face(static_cast<std::size_t>(degree));
    for (Index k = 0; k < degree; ++k) face[k] = next + k;
    std::shuffle(face.begin(), face.end(), rng);
    mesh.faces.addFace(std::span<const Index>(face));
    next += degree;
  }
  return mesh;
}

bool bitwiseEqual(const Positions& a, const Positions& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

struct Case {
  const char* extension;
  io::PlyEncoding encoding;
};

std::string caseName(const ::testing::TestParamInfo<Case>& info) {
  static const char* const kEncoding[] = {"ascii", "binary_le", "binary_be"};
  return std::string(info.param.extension + 1) + "_" + kEncoding[static_cast<int>(info.param.encoding)];
}

class RoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(RoundTrip, IsExactForAwkwardDoublesAndMixedPolygons) {
  const test::TempDir dir;
  const auto path = dir / (std::string("mesh") + GetParam().extension);
  const PolygonMesh mesh = awkwardMesh();
  WriteOptions write;
  write.plyEncoding = GetParam().encoding;
  writeMesh(path, mesh, write);
  ReadOptions read;
  read.validate = false;  // random geometry: only the round trip is tested here
  const PolygonMesh back = readMesh(path, read);
  EXPECT_TRUE(bitwiseEqual(back.vertices, mesh.vertices));
  EXPECT_TRUE(std::signbit(back.vertices(0, 0)));
  EXPECT_EQ(back.faces, mesh.faces);
}

TEST_P(RoundTrip, KeepsGeneratedMeshesValidAndIdentical) {
  const test::TempDir dir;
  const auto path = dir / (std::string("mesh") + GetParam().extension);
  WriteOptions write;
  write.plyEncoding = GetParam().encoding;
  for (const PolygonMesh& mesh : {generate::surfaceOfRevolution(24, 8), generate::hexagonalDome(4),
                                  generate::dodecahedron(), generate::hyparGrid(7)}) {
    writeMesh(path, mesh, write);
    const PolygonMesh back = readMesh(path);
    EXPECT_TRUE(bitwiseEqual(back.vertices, mesh.vertices));
    EXPECT_EQ(back.faces, mesh.faces);
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip,
                         ::testing::Values(Case{".obj", io::PlyEncoding::Ascii}, Case{".off", io::PlyEncoding::Ascii},
                                           Case{".ply", io::PlyEncoding::Ascii},
                                           Case{".ply", io::PlyEncoding::BinaryLittleEndian},
                                           Case{".ply", io::PlyEncoding::BinaryBigEndian}),
                         caseName);

TEST(MeshIO, PlyWritesWideCountsForLargePolygons) {
  PolygonMesh mesh;
  const Index n = 300;
  mesh.vertices.resize(n, 3);
  std::vector<Index> face(n);
  for (Index i = 0; i < n; ++i) {
    const double t = 2.0 * 3.141592653589793 * i / n;
    mesh.vertices.row(i) << std::cos(t), std::sin(t), 0.0;
    face[i] = i;
  }
  mesh.faces.addFace(std::span<const Index>(face));
  const test::TempDir dir;
  writeMesh(dir / "big.ply", mesh);
  EXPECT_EQ(readMesh(dir / "big.ply").faces.degree(0), n);
}

TEST(MeshIO, SharedArchitecturalMeshRoundTripsThroughEveryFormat) {
  PLANO_REQUIRE_SHARED_MESH(path, "dome_polyhedral_pattern.off");
  const PolygonMesh mesh = readMesh(path);
  const test::TempDir dir;
  for (const char* ext : {".obj", ".off", ".ply"}) {
    writeMesh(dir / (std::string("dome") + ext), mesh);
    const PolygonMesh back = readMesh(dir / (std::string("dome") + ext));
    EXPECT_TRUE(bitwiseEqual(back.vertices, mesh.vertices)) << ext;
    EXPECT_EQ(back.faces, mesh.faces) << ext;
  }
}

TEST(MeshIO, FailedWriteLeavesTheTargetUntouchedAndNoTemporaryFile) {
  const test::TempDir dir;
  const auto target = dir / "keep.obj";
  std::ofstream(target) << "previous content\n";
  PolygonMesh bad = generate::cube();
  bad.vertices(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(writeMesh(target, bad), Error);
  std::ifstream in(target);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "previous content");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

TEST(MeshIO, WriteIntoMissingFolderIsBadInput) {
  const test::TempDir dir;
  try {
    writeMesh(dir / "missing" / "m.obj", generate::cube());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos) << e.what();
  }
}

TEST(MeshIO, UnknownExtensionIsUsageError) {
  try {
    readMesh("mesh.stl");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

TEST(MeshIO, MissingFileAndDirectoryAreBadInput) {
  const test::TempDir dir;
  EXPECT_THROW(readMesh(dir / "absent.obj"), Error);
  std::filesystem::create_directory(dir / "folder.obj");
  try {
    readMesh(dir / "folder.obj");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos);
  }
}

TEST(MeshIO, ObjWriterUsesOneBasedIndicesAndShortestDoubles) {
  PolygonMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0.1, 0, 1, 1, 0, 0, 0, 1, 0;
  mesh.faces = FaceList({{0, 1, 2}});
  EXPECT_EQ(formatMesh(mesh, MeshFormat::Obj), "v 0.1 0 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(formatMesh(mesh, MeshFormat::Off), "OFF\n3 1 0\n0.1 0 1\n1 0 0\n0 1 0\n3 0 1 2\n");
}

}  // namespace
}  // namespace plano
