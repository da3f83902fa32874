#include "mesh/Validation.h"

#include <gtest/gtest.h>

#include <limits>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

PolygonMesh makeMesh(std::vector<Eigen::Vector3d> points, const std::vector<std::vector<Index>>& faces) {
  PolygonMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) mesh.vertices.row(static_cast<Eigen::Index>(i)) = points[i];
  mesh.faces = FaceList(faces);
  return mesh;
}

/// A 3 x 2 grid of unit quads in the xy-plane (vertices 0..11, row-major 4 per row), faces
/// counter-clockwise: a valid base to break one thing at a time.
PolygonMesh grid() {
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 4; ++i) points.emplace_back(i, j, 0.0);
  }
  std::vector<std::vector<Index>> faces;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 3; ++i) {
      const Index a = 4 * j + i;
      faces.push_back({a, a + 1, a + 5, a + 4});
    }
  }
  return makeMesh(points, faces);
}

std::vector<std::vector<Index>> polygons(const PolygonMesh& mesh) {
  std::vector<std::vector<Index>> result;
  for (Index f = 0; f < mesh.faceCount(); ++f) result.emplace_back(mesh.faces[f].begin(), mesh.faces[f].end());
  return result;
}

/// The single stored issue of `kind`; fails when there is none.
const ValidationIssue* findIssue(const ValidationReport& report, ValidationIssueKind kind) {
  for (const auto& issue : report.issues) {
    if (issue.kind == kind) return &issue;
  }
  ADD_FAILURE() << "no issue of kind " << toString(kind);
  return nullptr;
}

std::size_t countKind(const ValidationReport& report, ValidationIssueKind kind) {
  std::size_t n = 0;
  for (const auto& issue : report.issues) n += issue.kind == kind;
  return n;
}

PolygonMesh gridWithFaces(const std::vector<std::vector<Index>>& faces) {
  PolygonMesh m = grid();
  m.faces = FaceList(faces);
  return m;
}

TEST(Validation, GeneratedMeshesAreValid) {
  for (const PolygonMesh& mesh : {grid(), generate::cube(), generate::dodecahedron(), generate::hexagonalDome(3),
                                  generate::surfaceOfRevolution(16, 6), generate::hyparGrid(6)}) {
    const ValidationReport report = validate(mesh);
    EXPECT_EQ(report.status, ValidationStatus::Valid) << (report.issues.empty() ? "" : report.issues[0].message);
    EXPECT_NO_THROW(requireValid(mesh, "generated"));
  }
}

TEST(Validation, ReportsIndexOutOfRange) {
  auto faces = polygons(grid());
  faces[4][2] = 12;
  const ValidationReport report = validate(gridWithFaces(faces));
  const auto* issue = findIssue(report, ValidationIssueKind::IndexOutOfRange);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->face, 4);
  EXPECT_EQ(issue->vertex, 12);
  EXPECT_EQ(issue->message, "face 4: vertex index 12 out of range [0, 12)");
  EXPECT_EQ(report.status, ValidationStatus::Invalid);
}

TEST(Validation, ReportsNegativeIndexAsOutOfRange) {
  auto faces = polygons(grid());
  faces[0][0] = -1;
  const auto report = validate(gridWithFaces(faces));
  const auto* issue = findIssue(report, ValidationIssueKind::IndexOutOfRange);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->face, 0);
}

TEST(Validation, ReportsRepeatedVertex) {
  auto faces = polygons(grid());
  faces[1] = {1, 2, 6, 2};
  const auto report = validate(gridWithFaces(faces));
  const auto* issue = findIssue(report, ValidationIssueKind::RepeatedVertex);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "face 1 repeats vertex 2");
}

TEST(Validation, ReportsFaceWithTooFewVertices) {
  auto faces = polygons(grid());
  faces.push_back({0, 1});
  const auto report = validate(gridWithFaces(faces));
  const auto* issue = findIssue(report, ValidationIssueKind::TooFewVertices);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "face 6 has 2 vertices (at least 3 needed)");
}

TEST(Validation, ReportsNaNAndInfinity) {
  PolygonMesh mesh = grid();
  mesh.vertices(3, 1) = std::numeric_limits<double>::quiet_NaN();
  mesh.vertices(7, 2) = -std::numeric_limits<double>::infinity();
  const auto report = validate(mesh);
  ASSERT_EQ(countKind(report, ValidationIssueKind::NonFiniteCoordinate), 2u);
  EXPECT_EQ(report.issues[0].message, "vertex 3: coordinate y is NaN");
  EXPECT_EQ(report.issues[1].message, "vertex 7: coordinate z is infinite");
}

TEST(Validation, ReportsAbsurdMagnitude) {
  PolygonMesh mesh = grid();
  mesh.vertices(5, 0) = 1e308;
  const auto report = validate(mesh);
  const auto* issue = findIssue(report, ValidationIssueKind::HugeCoordinate);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->vertex, 5);
  EXPECT_NE(issue->message.find("vertex 5: coordinate x = 1e+308 exceeds"), std::string::npos) << issue->message;
}

TEST(Validation, ReportsNonManifoldEdge) {
  auto points = std::vector<Eigen::Vector3d>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  const auto report = validate(makeMesh(points, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}));
  const auto* issue = findIssue(report, ValidationIssueKind::NonManifoldEdge);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "edge (0, 1) is shared by 3 faces (0, 1, 2): non-manifold edge");
}

TEST(Validation, ReportsNonManifoldVertexWithTwoFans) {
  // Two triangles meeting only at vertex 0 (bow tie).
  auto points = std::vector<Eigen::Vector3d>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  const auto report = validate(makeMesh(points, {{0, 1, 2}, {0, 3, 4}}));
  const auto* issue = findIssue(report, ValidationIssueKind::NonManifoldVertex);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "vertex 0 is non-manifold: its faces form 2 separate fans");
  EXPECT_EQ(report.errorCount, 1u);
}

TEST(Validation, ReportsInconsistentOrientation) {
  auto faces = polygons(grid());
  std::reverse(faces[4].begin(), faces[4].end());
  const auto report = validate(gridWithFaces(faces));
  EXPECT_EQ(countKind(report, ValidationIssueKind::InconsistentOrientation), 3u);  // face 4 has 3 interior edges
  const auto* issue = findIssue(report, ValidationIssueKind::InconsistentOrientation);
  ASSERT_NE(issue, nullptr);
  EXPECT_NE(issue->message.find("inconsistent orientation"), std::string::npos);
  EXPECT_EQ(issue->face, 4);
}

TEST(Validation, ReportsZeroAreaFace) {
  PolygonMesh mesh = grid();
  // Collapse face 0 onto a segment: every corner on the x axis.
  mesh.vertices.row(4) << 0.5, 0, 0;
  mesh.vertices.row(5) << 0.25, 0, 0;
  const auto report = validate(mesh);
  const auto* issue = findIssue(report, ValidationIssueKind::ZeroAreaFace);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "face 0 has zero area");
}

TEST(Validation, ReportsCollinearCornersOfQuad) {
  PolygonMesh mesh = grid();
  // Face 0 = (0, 1, 5, 4): moving vertex 4 onto the x axis puts corners 3, 0, 1 on a line.
  mesh.vertices.row(4) << -1, 0, 0;
  const auto report = validate(mesh);
  const auto* issue = findIssue(report, ValidationIssueKind::CollinearCorners);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->severity, Severity::Error);
  EXPECT_EQ(issue->face, 0);
  EXPECT_NE(issue->message.find("are collinear"), std::string::npos);
}

TEST(Validation, ReportsCoincidentCornersOfQuad) {
  PolygonMesh mesh = grid();
  mesh.vertices.row(5) = mesh.vertices.row(1);  // face 0 = (0, 1, 5, 4): corners 1 and 2 coincide
  const auto report = validate(mesh);
  const auto* issue = findIssue(report, ValidationIssueKind::CollinearCorners);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "face 0: corners 1 and 2 (vertices 1, 5) coincide");
}

TEST(Validation, CollinearCornersInLargerPolygonIsWarning) {
  // A hexagon whose corners 0, 1, 2 are on a line: a panel with a straight run.
  auto points = std::vector<Eigen::Vector3d>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 2, 0}, {0, 1, 0}};
  const auto report = validate(makeMesh(points, {{0, 1, 2, 3, 4, 5}}));
  EXPECT_EQ(report.status, ValidationStatus::ValidWithWarnings);
  const auto* issue = findIssue(report, ValidationIssueKind::CollinearCorners);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->severity, Severity::Warning);
}

TEST(Validation, ReportsDuplicateFace) {
  auto faces = polygons(grid());
  faces.push_back({5, 6, 2, 1});  // face 1 rotated
  const auto report = validate(gridWithFaces(faces));
  const auto* issue = findIssue(report, ValidationIssueKind::DuplicateFace);
  ASSERT_NE(issue, nullptr);
  EXPECT_EQ(issue->message, "face 6 duplicates face 1 (same vertices)");
  EXPECT_EQ(report.errorCount, 1u);  // its shared edges are not reported a second time
}

TEST(Validation, IsolatedVertexIsOnlyAWarning) {
  PolygonMesh mesh = grid();
  mesh.vertices.conservativeResize(13, 3);
  mesh.vertices.row(12) << 9, 9, 9;
  const auto report = validate(mesh);
  EXPECT_EQ(report.status, ValidationStatus::ValidWithWarnings);
  EXPECT_EQ(report.errorCount, 0u);
  EXPECT_EQ(report.warningCount, 1u);
  EXPECT_EQ(report.issues.at(0).message, "vertex 12 is isolated (in no face)");
  EXPECT_NO_THROW(requireValid(mesh, "grid"));
}

TEST(Validation, CapsStoredIssuesButCountsAll) {
  PolygonMesh mesh = grid();
  mesh.vertices.conservativeResize(1012, 3);
  mesh.vertices.bottomRows(1000).setOnes();
  ValidationSettings settings;
  settings.maxIssuesPerKind = 10;
  const auto report = validate(mesh, settings);
  EXPECT_EQ(report.warningCount, 1000u);
  EXPECT_EQ(report.issues.size(), 10u);
}

TEST(Validation, RequireValidNamesSourceAndFirstErrors) {
  auto faces = polygons(grid());
  faces[0][1] = 0;
  faces[2][0] = 99;
  PolygonMesh mesh = gridWithFaces(faces);
  mesh.vertices(11, 0) = std::numeric_limits<double>::quiet_NaN();
  try {
    requireValid(mesh, "in.obj");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_EQ(std::string(e.what()),
              "in.obj: vertex 11: coordinate x is NaN; face 0 repeats vertex 0; face 2: vertex index 99 out of range "
              "[0, 12)");
  }
}

TEST(Validation, NeverThrowsOnEmptyMesh) {
  const auto report = validate(PolygonMesh{});
  EXPECT_EQ(report.status, ValidationStatus::Valid);
}

TEST(Validation, SharedArchitecturalMeshesAreValid) {
  for (const char* name : {"yas_island.off", "gitter.off", "enneper_hex.off", "double_torus_quads.off", "hypar.obj",
                           "spot_quad.obj", "spot_control.obj", "dome_polyhedral_pattern.off"}) {
    PLANO_REQUIRE_SHARED_MESH(path, name);
    const auto report = validate(readMesh(path));
    EXPECT_TRUE(report.valid()) << name << ": " << report.issues.at(0).message;
  }
}

}  // namespace
}  // namespace plano
