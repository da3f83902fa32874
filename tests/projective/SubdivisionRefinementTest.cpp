#include <gtest/gtest.h>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "projective/QuadRefinement.h"

namespace plano::projective {
namespace {

Index eulerCharacteristic(const FaceList& faces, Index vertexCount) {
  return vertexCount - faces.cornerCount() / 2 + faces.size();  // closed meshes only
}

TEST(SubdivisionRefinement, CubeSplitsEveryQuadIntoFourAndKeepsCoarseIndices) {
  const PolygonMesh cube = generate::cube(2.0);
  const QuadRefinement r = refineQuads(cube.faces, cube.vertexCount());
  EXPECT_EQ(r.coarseEdges.edgeCount(), 12);
  EXPECT_EQ(r.fineVertexCount(), 8 + 12 + 6);
  ASSERT_EQ(r.fineFaces.size(), 24);
  EXPECT_EQ(r.fineFaces.maxDegree(), 4);
  EXPECT_EQ(eulerCharacteristic(r.fineFaces, r.fineVertexCount()), 2);
  for (Index f = 0; f < cube.faceCount(); ++f) {
    for (Index i = 0; i < 4; ++i) {
      const Index fine = cube.faces.offsets()[f] + i;
      EXPECT_EQ(r.parentFace[fine], f);
      // The fine quad of a corner starts at that coarse vertex and contains the face point.
      EXPECT_EQ(r.fineFaces[fine][0], cube.faces[f][i]);
      EXPECT_EQ(r.fineFaces[fine][2], r.facePoint(f));
    }
  }
  // The refined mesh is again a consistently oriented closed manifold.
  const EdgeTopology fineEdges = buildEdgeTopology(r.fineFaces, r.fineVertexCount());
  for (Index e = 0; e < fineEdges.edgeCount(); ++e) EXPECT_FALSE(fineEdges.isBoundary(e));
}

TEST(SubdivisionRefinement, PentagonsBecomeFiveQuads) {
  const PolygonMesh d = generate::dodecahedron();
  const QuadRefinement r = refineQuads(d.faces, d.vertexCount());
  EXPECT_EQ(r.fineFaces.size(), 60);
  EXPECT_EQ(r.fineVertexCount(), 20 + 30 + 12);
  EXPECT_EQ(eulerCharacteristic(r.fineFaces, r.fineVertexCount()), 2);
}

TEST(SubdivisionRefinement, TrivialPositionsAreMidpointsAndKeepPlanarFacesPlanar) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(8, 3);
  const QuadRefinement r = refineQuads(mesh.faces, mesh.vertexCount());
  PolygonMesh fine{trivialRefinementPositions(r, mesh.faces, mesh.vertices), r.fineFaces};
  EXPECT_EQ(fine.vertices.topRows(mesh.vertexCount()), mesh.vertices);
  for (Index e = 0; e < r.coarseEdges.edgeCount(); ++e) {
    const auto [a, b] = r.coarseEdges.edges[e];
    const Eigen::RowVector3d mid = 0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b));
    EXPECT_LT((fine.vertices.row(r.edgePoint(e)) - mid).norm(), 1e-15);
  }
  // A planar trapezoid cut through its midpoints gives planar quads.
  EXPECT_LT(planarityStats(fine).max, 1e-10);
}

TEST(SubdivisionRefinement, OpenGridHasBoundaryEdges) {
  const PolygonMesh grid = generate::hyparGrid(3);
  const EdgeTopology t = buildEdgeTopology(grid.faces, grid.vertexCount());
  Index boundary = 0;
  for (Index e = 0; e < t.edgeCount(); ++e) boundary += t.isBoundary(e) ? 1 : 0;
  EXPECT_EQ(t.edgeCount(), 2 * 3 * 4);
  EXPECT_EQ(boundary, 12);
}

TEST(SubdivisionRefinement, RejectsNonManifoldEdgeNamingIt) {
  const FaceList faces({{0, 1, 2, 3}, {1, 0, 4, 5}, {0, 1, 6, 7}});
  try {
    refineQuads(faces, 8);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("edge (0, 1)"), std::string::npos) << e.what();
  }
}

TEST(SubdivisionRefinement, RejectsInconsistentOrientation) {
  const FaceList faces({{0, 1, 2, 3}, {0, 1, 4, 5}});
  try {
    refineQuads(faces, 6);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("orientation"), std::string::npos) << e.what();
  }
}

TEST(SubdivisionRefinement, RejectsBadVertexIndicesAndDegenerateFaces) {
  EXPECT_THROW(refineQuads(FaceList({{0, 1, 2, 9}}), 4), Error);
  EXPECT_THROW(refineQuads(FaceList({{0, 1, 1, 2}}), 4), Error);
  EXPECT_THROW(refineQuads(FaceList({{0, 1}}), 4), Error);
  EXPECT_THROW(refineQuads(FaceList(), 4), Error);
}

}  // namespace
}  // namespace plano::projective
