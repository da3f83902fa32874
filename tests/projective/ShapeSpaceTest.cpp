#include "projective/ShapeSpace.h"

#include <gtest/gtest.h>

#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/ProjectiveTestHelpers.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

TEST(ShapeSpace, NormalizesToUnitDiagonalAroundTheBoxCentre) {
  PolygonMesh mesh = generate::translationalSurface(4, 3);
  mesh.vertices = (mesh.vertices * 250.0).rowwise() + Eigen::RowVector3d(1e3, -40.0, 7.0);
  const ShapeSpace space(mesh);
  EXPECT_NEAR(boundingBoxDiagonal(space.basePositions()), 1.0, 1e-12);
  const Eigen::RowVector3d lo = space.basePositions().colwise().minCoeff();
  const Eigen::RowVector3d hi = space.basePositions().colwise().maxCoeff();
  EXPECT_LT((lo + hi).norm(), 1e-12);
  EXPECT_LT(test::maxAbsDifference(space.normalization().toWorld(space.basePositions()), mesh.vertices), 1e-9);
}

TEST(ShapeSpace, IdentityMapsReproduceTheBaseMesh) {
  const PolygonMesh mesh = generate::dodecahedron();
  const ShapeSpace space(mesh);
  const FaceMaps identity = space.identityMaps();
  EXPECT_LT(test::maxAbsDifference(space.positions(identity.maps), mesh.vertices), 1e-14);
  for (double s : space.inducedReciprocalScales(identity.maps)) EXPECT_EQ(s, 1.0);
}

TEST(ShapeSpace, OneProjectiveMapOnEveryFaceGivesTheProjectiveImage) {
  // Works for pentagons (dodecahedron) and hexagons (dome) alike: one map per face.
  for (const PolygonMesh& mesh : {generate::dodecahedron(), generate::hexagonalDome(2)}) {
    const ShapeSpace space(mesh);
    const Eigen::Matrix4d H = test::samplePerspective();
    const std::vector<Eigen::Matrix4d> maps(space.faceCount(), H);
    const Positions expected = space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), H));
    EXPECT_LT(test::maxAbsDifference(space.positions(maps), expected), 1e-12);
    EXPECT_LT(space.maxCornerDisagreement(maps), 1e-14);
  }
}

TEST(ShapeSpace, AveragesDisagreeingCornerImages) {
  const PolygonMesh mesh = generate::translationalSurface(2, 1);  // two quads sharing an edge
  const ShapeSpace space(mesh);
  std::vector<Eigen::Matrix4d> maps(2, Eigen::Matrix4d::Identity());
  maps[1](3, 0) = 0.1;  // face 1 translated by 0.1 along x (normalized units)
  const Positions p = space.normalizedPositions(maps);
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const double expected = space.vertexDegree(v) == 2 ? 0.05 : (space.cornerFace(space.cornersOfVertex()[space.vertexCornerOffsets()[v]]) == 1 ? 0.1 : 0.0);
    EXPECT_NEAR(p(v, 0) - space.basePositions()(v, 0), expected, 1e-14) << "vertex " << v;
  }
  EXPECT_NEAR(space.maxCornerDisagreement(maps), 0.05, 1e-14);
}

TEST(ShapeSpace, RejectsBadFacesNamingThem) {
  PolygonMesh mesh = generate::cube();
  mesh.faces.addFace({0, 1});
  try {
    const ShapeSpace space(mesh);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("face 6"), std::string::npos) << e.what();
  }
  PolygonMesh nan = generate::cube();
  nan.vertices(3, 1) = std::nan("");
  EXPECT_THROW(ShapeSpace{nan}, Error);
}

TEST(ShapeSpace, MapSendingAVertexToInfinityIsANumericalError) {
  const ShapeSpace space(generate::cube());
  std::vector<Eigen::Matrix4d> maps(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::RowVector3d p = space.basePositions().row(0);
  // Column 3 such that (p0, 1) . A[:, 3] = 0 for face 0's copy of vertex 0.
  const Index f = space.cornerFace(space.cornersOfVertex()[space.vertexCornerOffsets()[0]]);
  maps[f].block<3, 1>(0, 3) = -p.transpose() / p.squaredNorm();
  try {
    space.positions(maps);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("vertex 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plano::projective
