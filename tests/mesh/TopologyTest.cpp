#include "mesh/Topology.h"

#include <gtest/gtest.h>

#include <set>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

/// Checks that must hold for every topology: each corner's edge joins the corner's
/// vertex and the next one, and the edge's sides point back at that corner.
void expectConsistent(const FaceList& faces, const MeshTopology& t) {
  ASSERT_EQ(t.cornerCount(), faces.cornerCount());
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    const Index n = static_cast<Index>(face.size());
    for (Index k = 0; k < n; ++k) {
      const Index e = t.faceEdge(f, k);
      const std::set<Index> expected = {face[k], face[(k + 1) % n]};
      EXPECT_EQ((std::set<Index>{t.edgeVertex(e, 0), t.edgeVertex(e, 1)}), expected) << "face " << f << " corner " << k;
      const int side = t.edgeFace(e, 0) == f ? 0 : 1;
      EXPECT_EQ(t.edgeFace(e, side), f);
      EXPECT_EQ(t.edgeCorner(e, side), k);
    }
  }
  Index incidences = 0;
  for (Index v = 0; v < t.vertexCount(); ++v) {
    const auto fs = t.facesOfVertex(v);
    const auto ks = t.cornersOfVertex(v);
    for (std::size_t i = 0; i < fs.size(); ++i) EXPECT_EQ(faces[fs[i]][ks[i]], v);
    incidences += static_cast<Index>(fs.size());
  }
  EXPECT_EQ(incidences, faces.cornerCount());
}

TEST(Topology, CubeIsClosedGenusZeroSphere) {
  const PolygonMesh cube = generate::cube();
  const MeshTopology t(cube.faces, cube.vertexCount());
  expectConsistent(cube.faces, t);
  EXPECT_EQ(t.vertexCount(), 8);
  EXPECT_EQ(t.edgeCount(), 12);
  EXPECT_EQ(t.faceCount(), 6);
  EXPECT_EQ(t.cornerCount(), 24);
  EXPECT_EQ(t.boundaryCount(), 0);
  EXPECT_EQ(t.boundaryVertexCount(), 0);
  EXPECT_EQ(t.eulerCharacteristic(), 2);
  EXPECT_EQ(t.genus(), 0);
  EXPECT_EQ(t.componentCount(), 1);
  EXPECT_TRUE(t.inconsistentEdges().empty());
  for (Index f = 0; f < 6; ++f) EXPECT_EQ(t.neighborsOfFace(f).size(), 4u);
  for (Index v = 0; v < 8; ++v) EXPECT_EQ(t.vertexFanCounts()[v], 1);
}

TEST(Topology, ConsistentlyOrientedNeighboursTraverseSharedEdgeOppositely) {
  const PolygonMesh mesh = generate::dodecahedron();
  const MeshTopology t(mesh.faces, mesh.vertexCount());
  expectConsistent(mesh.faces, t);
  EXPECT_EQ(t.edgeCount(), 30);
  EXPECT_EQ(t.genus(), 0);
  for (Index e = 0; e < t.edgeCount(); ++e) {
    const auto f1 = mesh.faces[t.edgeFace(e, 1)];
    const Index k1 = t.edgeCorner(e, 1);
    // Side 1 owns the edge from v1 to v0.
    EXPECT_EQ(f1[k1], t.edgeVertex(e, 1));
    EXPECT_EQ(f1[(k1 + 1) % f1.size()], t.edgeVertex(e, 0));
  }
}

TEST(Topology, GridHasOneBoundaryLoopInFaceDirection) {
  const Index n = 5;
  const PolygonMesh grid = generate::hyparGrid(n);
  const MeshTopology t(grid.faces, grid.vertexCount());
  expectConsistent(grid.faces, t);
  EXPECT_EQ(t.edgeCount(), 2 * n * (n + 1));
  EXPECT_EQ(t.boundaryCount(), 1);
  EXPECT_EQ(t.boundaryEdgeCount(), 4 * n);
  EXPECT_EQ(t.boundaryVertexCount(), 4 * n);
  EXPECT_EQ(t.eulerCharacteristic(), 1);
  EXPECT_EQ(t.genus(), 0);
  const auto loop = t.boundaryLoop(0);
  ASSERT_EQ(loop.size(), static_cast<std::size_t>(4 * n));
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Index e = t.loopEdges()[t.loopOffsets()[0] + i];
    EXPECT_TRUE(t.isBoundaryEdge(e));
    // The loop walks each boundary edge in its face's direction.
    EXPECT_EQ(t.edgeVertex(e, 0), loop[i]);
    EXPECT_EQ(t.edgeVertex(e, 1), loop[(i + 1) % loop.size()]);
  }
}

TEST(Topology, CylinderHasTwoBoundaries) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(12, 4);
  const MeshTopology t(mesh.faces, mesh.vertexCount());
  expectConsistent(mesh.faces, t);
  EXPECT_EQ(t.boundaryCount(), 2);
  EXPECT_EQ(t.eulerCharacteristic(), 0);
  EXPECT_EQ(t.genus(), 0);
  EXPECT_EQ(t.boundaryLoop(0).size(), 12u);
  EXPECT_EQ(t.boundaryLoop(1).size(), 12u);
}

TEST(Topology, EdgesAreNumberedByFirstAppearance) {
  // Two quads sharing the edge (1, 4).
  const FaceList faces({{0, 1, 4, 3}, {1, 2, 5, 4}});
  const MeshTopology t(faces, 6);
  ASSERT_EQ(t.edgeCount(), 7);
  const std::vector<Index> expected = {0, 1, 1, 4, 4, 3, 3, 0, 1, 2, 2, 5, 5, 4};
  EXPECT_EQ(t.edgeVertices(), expected);
  EXPECT_EQ(t.faceEdge(1, 3), 1);  // corner 3 of face 1 owns 4 -> 1, the shared edge
  EXPECT_EQ(t.edgeFace(1, 0), 0);
  EXPECT_EQ(t.edgeFace(1, 1), 1);
  EXPECT_EQ(t.edgeCorner(1, 1), 3);
  EXPECT_EQ(t.boundaryEdgeCount(), 6);
  EXPECT_EQ(t.faceNeighborOffsets(), (std::vector<Index>{0, 1, 2}));
  EXPECT_EQ(t.faceNeighbors(), (std::vector<Index>{1, 0}));
}

TEST(Topology, CountsComponentsAndIsolatedVertices) {
  // Two separate triangles and one vertex in no face.
  const FaceList faces({{0, 1, 2}, {3, 4, 5}});
  const MeshTopology t(faces, 7);
  EXPECT_EQ(t.componentCount(), 2);
  EXPECT_EQ(t.isolatedVertexCount(), 1);
  EXPECT_EQ(t.vertexComponents()[6], kNoFace);
  EXPECT_EQ(t.faceComponents(), (std::vector<Index>{0, 1}));
  EXPECT_EQ(t.components()[1].vertices, 3);
  EXPECT_EQ(t.components()[1].boundaries, 1);
  EXPECT_EQ(t.genus(), 0);
  EXPECT_EQ(t.eulerCharacteristic(), 7 - 6 + 2);
}

TEST(Topology, DetectsFlippedFaceAsInconsistentEdges) {
  PolygonMesh cube = generate::cube();
  std::vector<std::vector<Index>> polygons;
  for (Index f = 0; f < cube.faceCount(); ++f) polygons.emplace_back(cube.faces[f].begin(), cube.faces[f].end());
  std::reverse(polygons[2].begin(), polygons[2].end());
  const MeshTopology t(FaceList(polygons), cube.vertexCount());
  EXPECT_EQ(t.inconsistentEdges().size(), 4u);
  EXPECT_FALSE(t.genus().has_value());
}

TEST(Topology, CountsTwoFansAtNonManifoldVertex) {
  // Two triangles touching only at vertex 0 (bow tie).
  const FaceList faces({{0, 1, 2}, {0, 3, 4}});
  const MeshTopology t(faces, 5);
  EXPECT_EQ(t.vertexFanCounts()[0], 2);
  EXPECT_EQ(t.vertexFanCounts()[1], 1);
  EXPECT_EQ(t.componentCount(), 1);
  EXPECT_EQ(t.boundaryCount(), 2);
  EXPECT_FALSE(t.genus().has_value());
}

TEST(Topology, RejectsNonManifoldEdgeNamingIt) {
  const FaceList faces({{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  try {
    MeshTopology t(faces, 5);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("edge (0, 1) is shared by 3 faces (0, 1, 2)"), std::string::npos) << e.what();
  }
}

TEST(Topology, RejectsMalformedFaces) {
  EXPECT_THROW(MeshTopology(FaceList({{0, 1, 5}}), 3), Error);
  EXPECT_THROW(MeshTopology(FaceList({{0, 1, -1}}), 3), Error);
  EXPECT_THROW(MeshTopology(FaceList({{0, 1}}), 3), Error);
  EXPECT_THROW(MeshTopology(FaceList({{0, 1, 2, 1}}), 3), Error);
}

TEST(Topology, EmptyMesh) {
  const MeshTopology t(FaceList(), 0);
  EXPECT_EQ(t.edgeCount(), 0);
  EXPECT_EQ(t.componentCount(), 0);
  EXPECT_EQ(t.boundaryCount(), 0);
  EXPECT_FALSE(t.genus().has_value());
}

TEST(Topology, DoubleTorusHasGenusTwo) {
  PLANO_REQUIRE_SHARED_MESH(path, "double_torus_quads.off");
  const PolygonMesh mesh = readMesh(path);
  const MeshTopology t(mesh.faces, mesh.vertexCount());
  expectConsistent(mesh.faces, t);
  EXPECT_EQ(t.boundaryCount(), 0);
  EXPECT_EQ(t.eulerCharacteristic(), -2);
  EXPECT_EQ(t.genus(), 2);
}

TEST(Topology, GitterHasFourHolesAndOuterBoundary) {
  PLANO_REQUIRE_SHARED_MESH(path, "gitter.off");
  const PolygonMesh mesh = readMesh(path);
  const MeshTopology t(mesh.faces, mesh.vertexCount());
  expectConsistent(mesh.faces, t);
  EXPECT_EQ(t.boundaryCount(), 5);
  EXPECT_EQ(t.componentCount(), 1);
  EXPECT_EQ(t.genus(), 0);
}

}  // namespace
}  // namespace plano
