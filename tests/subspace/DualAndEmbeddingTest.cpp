// Polar dual (linear-spaces paper, §3 "Dual exploration") and Tutte embedding + affine
// lifting (§4 "Creating an initial PM").
#include <gtest/gtest.h>

#include "core/Error.h"
#include "subspace/AffineLifting.h"
#include "subspace/PolarDual.h"
#include "subspace/SubspaceTestSupport.h"
#include "subspace/TutteEmbedding.h"
#include "support/TestMeshes.h"

namespace plano::subspace {
namespace {

using test::maxPlanarity;

bool sameUpToRotation(std::span<const Index> a, std::span<const Index> b) {
  if (a.size() != b.size()) return false;
  for (std::size_t shift = 0; shift < a.size(); ++shift) {
    bool same = true;
    for (std::size_t i = 0; i < a.size() && same; ++i) same = a[i] == b[(i + shift) % b.size()];
    if (same) return true;
  }
  return false;
}

PolygonMesh offCentre(PolygonMesh mesh) {
  mesh.vertices.rowwise() += Eigen::RowVector3d(0.05, -0.03, 0.02);
  return mesh;
}

TEST(PolarDual, DualOfTheDualIsTheOriginalMesh) {
  for (const PolygonMesh& mesh : {offCentre(generate::cube()), offCentre(generate::dodecahedron()),
                                  test::projectiveImage(generate::cube())}) {
    const PolygonMesh dual = polarDual(mesh);
    EXPECT_EQ(dual.vertexCount(), mesh.faceCount());
    EXPECT_EQ(dual.faceCount(), mesh.vertexCount());
    EXPECT_LE(maxPlanarity(dual, dual.vertices), 1e-9);
    const PolygonMesh back = polarDual(dual);
    ASSERT_EQ(back.vertexCount(), mesh.vertexCount());
    EXPECT_LE(test::maxAbsDifference(back.vertices, mesh.vertices), 1e-9);
    ASSERT_EQ(back.faceCount(), mesh.faceCount());
    for (Index f = 0; f < mesh.faceCount(); ++f) EXPECT_TRUE(sameUpToRotation(back.faces[f], mesh.faces[f])) << f;
  }
}

TEST(PolarDual, PrimalIsRecoveredFromEditedDualVerticesAndStaysPolyhedral) {
  const PolygonMesh mesh = offCentre(generate::dodecahedron());
  const PolygonMesh dual = polarDual(mesh);
  // The dual of a 3-regular mesh is a triangle mesh: any dual positions give planar primal faces.
  const Positions edited = test::perturbed(dual.vertices, 0.02);
  const Positions X = primalFromDual(mesh.faces, edited, mesh.vertices);
  EXPECT_LE(maxPlanarity(mesh, X), 1e-9);
  EXPECT_GT((X - mesh.vertices).norm(), 1e-3);
  EXPECT_LE(test::maxAbsDifference(primalFromDual(mesh.faces, dual.vertices, mesh.vertices), mesh.vertices), 1e-9);
}

TEST(PolarDual, FacePlaneThroughTheOriginIsReportedByFace) {
  const PolygonMesh mesh = generate::translationalSurface(2, 2);  // Lies near z = 0, planes through the origin.
  PolygonMesh flat = mesh;
  flat.vertices.col(2).setZero();
  try {
    polarDual(flat);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("face 0"), std::string::npos);
  }
}

TEST(TutteEmbedding, DiskMeshIsEmbeddedFlatWithoutFlippedFaces) {
  for (const PolygonMesh& mesh : {generate::translationalSurface(6, 4), generate::hexagonalDome(3)}) {
    TutteInfo info;
    const Positions X = tutteEmbedding(mesh.faces, mesh.vertexCount(), {}, &info);
    EXPECT_EQ(info.flippedFaces, 0);
    EXPECT_EQ(X.col(2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(info.boundaryVertices + info.interiorVertices, mesh.vertexCount());
    EXPECT_LE(maxPlanarity(mesh, X), 1e-9);
  }
}

TEST(TutteEmbedding, ClosedMeshIsRejected) {
  const PolygonMesh cube = generate::cube();
  EXPECT_THROW(tutteEmbedding(cube.faces, cube.vertexCount()), Error);
}

TEST(AffineLifting, GivesAFlatQuadMeshPlanarHeight) {
  const PolygonMesh grid = generate::translationalSurface(6, 6);
  const PolygonMesh flat{tutteEmbedding(grid.faces, grid.vertexCount()), grid.faces};
  for (LiftKind kind : {LiftKind::Eigenshape, LiftKind::Handle}) {
    LiftSettings settings;
    settings.kind = kind;
    LiftInfo info;
    const PolygonMesh lifted = liftWithAffineSpace(flat, settings, &info);
    EXPECT_GT(info.liftings, 0);
    EXPECT_NEAR(info.maxHeight, settings.height * boundingBoxDiagonal(flat.vertices), 1e-12);
    EXPECT_LE(maxPlanarity(lifted, lifted.vertices), 1e-9);
    // Not a plane: the heights are not an affine function of (x, y).
    Eigen::MatrixXd A(flat.vertexCount(), 3);
    A << Eigen::VectorXd::Ones(flat.vertexCount()), flat.vertices.col(0), flat.vertices.col(1);
    const Eigen::VectorXd z = lifted.vertices.col(2);
    EXPECT_GT((A * A.colPivHouseholderQr().solve(z) - z).norm(), 1e-3);
  }
}

TEST(AffineLifting, SingleFaceOnlyHasPlanarLiftings) {
  PolygonMesh quad;
  quad.vertices.resize(4, 3);
  quad.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  quad.faces.addFace({0, 1, 2, 3});
  try {
    liftWithAffineSpace(quad);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
  }
}

}  // namespace
}  // namespace plano::subspace
