// Eigenshapes, sparse and fundamental shapes, constrained projection and face
// reassignment (linear-spaces paper, §2 Fig. 4 and §3).
#include <gtest/gtest.h>

#include "core/Error.h"
#include "subspace/ConstrainedSubspace.h"
#include "subspace/Eigenshapes.h"
#include "subspace/FundamentalShapes.h"
#include "subspace/MeshLaplacian.h"
#include "subspace/NonMaximalFaces.h"
#include "subspace/SparseShapes.h"
#include "subspace/SubspaceTestSupport.h"
#include "support/TestMeshes.h"

namespace plano::subspace {
namespace {

using test::maxPlanarity;

TEST(Eigenshapes, AreOrthonormalInTheSpaceAndSortedByFrequency) {
  const PolygonMesh mesh = generate::translationalSurface(6, 5);
  const compute::SparseMatrix L = uniformLaplacian(mesh.faces, mesh.vertexCount());
  for (SpaceKind kind : {SpaceKind::Affine, SpaceKind::Parallel, SpaceKind::Vertical}) {
    const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
    EigenshapeSettings settings;
    settings.count = 9;
    const Eigenshapes shapes = computeEigenshapes(space.N, L, settings);
    ASSERT_EQ(shapes.count(), 9) << toString(kind);
    Eigen::MatrixXd X(3 * mesh.vertexCount(), shapes.count());
    for (Index k = 0; k < shapes.count(); ++k) {
      const Positions Xk = space.N.shape(shapes.coefficients.col(k));
      X.col(k) = Eigen::Map<const Eigen::VectorXd>(Xk.data(), Xk.size());
      EXPECT_LE(space.B.residual(Xk), 1e-9) << toString(kind) << " shape " << k;
      // Rayleigh quotient recomputed from the shape itself.
      const double rayleigh = (Xk.transpose() * (L * Xk)).trace() / Xk.squaredNorm();
      EXPECT_NEAR(rayleigh, shapes.frequencies[k], 1e-9) << toString(kind) << " shape " << k;
      if (k > 0) {
        EXPECT_LE(shapes.frequencies[k - 1], shapes.frequencies[k] + 1e-12);
      }
    }
    EXPECT_LE((X.transpose() * X - Eigen::MatrixXd::Identity(9, 9)).cwiseAbs().maxCoeff(), 1e-9) << toString(kind);
  }
}

/// The eigenshapes of a side x side grid's space by the dense solver and by the iterative
/// one (denseLimit 0), with the iterative one's info.
struct DenseAndIterative {
  Eigenshapes dense, iterative;
  EigenshapeInfo info;
};

DenseAndIterative eigenshapesBothWays(Index side, SpaceKind kind, Index count) {
  const PolygonMesh mesh = generate::translationalSurface(side, side);
  const compute::SparseMatrix L = uniformLaplacian(mesh.faces, mesh.vertexCount());
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(kind, mesh.faceCount()));
  EigenshapeSettings dense, iterative;
  dense.count = iterative.count = count;
  iterative.denseLimit = 0;
  DenseAndIterative out;
  out.dense = computeEigenshapes(space.N, L, dense);
  out.iterative = computeEigenshapes(space.N, L, iterative, &out.info);
  return out;
}

TEST(Eigenshapes, SpectraAgreesWithTheDenseSolver) {
  const DenseAndIterative r = eigenshapesBothWays(8, SpaceKind::Parallel, 6);
  EXPECT_FALSE(r.info.dense);
  EXPECT_LE((r.dense.frequencies - r.iterative.frequencies).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Eigenshapes, ShiftInvertLanczosFindsTheZeroFrequenciesAndTheDenseSolversShapes) {
  // The affine space of a grid holds the translations (frequency 0, once per coordinate) and
  // a cluster of low frequencies: the iteration works on (R + shift)^-1, where they are the
  // largest eigenvalues and far apart.
  const DenseAndIterative r = eigenshapesBothWays(14, SpaceKind::Affine, 12);
  const Eigenshapes& a = r.dense;
  const Eigenshapes& b = r.iterative;
  ASSERT_FALSE(r.info.dense);
  EXPECT_LE(r.info.iterations, 5);
  EXPECT_LE(b.frequencies.head(3).cwiseAbs().maxCoeff(), 1e-10);
  // Rayleigh quotients of the Ritz vectors (4e-16 here); the Ritz values themselves were off
  // by up to 1.3e-9 on some machines.
  EXPECT_LE((a.frequencies - b.frequencies).cwiseAbs().maxCoeff(), 1e-12);
  // The same shapes: each of b's lies in the span of a's eigenshapes of its frequency (but
  // the highest frequency, whose eigenspace the count may cut: the square grid's symmetry
  // makes eigenvalues double).
  for (Index k = 0; k < b.count() && b.frequencies[k] < a.frequencies.maxCoeff() - 1e-6; ++k) {
    Eigen::MatrixXd sameFrequency(a.coefficients.rows(), 0);
    for (Index j = 0; j < a.count(); ++j) {
      if (std::abs(a.frequencies[j] - b.frequencies[k]) > 1e-6) continue;
      sameFrequency.conservativeResize(Eigen::NoChange, sameFrequency.cols() + 1);
      sameFrequency.rightCols(1) = a.coefficients.col(j);
    }
    const Eigen::VectorXd w = b.coefficients.col(k);
    EXPECT_LE((w - sameFrequency * (sameFrequency.transpose() * w)).norm(), 1e-6) << k;
  }
}

TEST(Eigenshapes, BandPassStaysPolyhedral) {
  const PolygonMesh mesh = generate::hexagonalDome(3);
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Vertical, mesh.faceCount()));
  const Eigenshapes shapes = computeEigenshapes(space.N, uniformLaplacian(mesh.faces, mesh.vertexCount()));
  const Positions base = space.N.project(mesh.vertices);
  const Positions X = bandPass(space.N, shapes, base, 3, 8, 0.05);
  EXPECT_GT((X - base).norm(), 1e-3);
  EXPECT_LE(maxPlanarity(mesh, X), 1e-9);
  EXPECT_THROW(bandPass(space.N, shapes, base, 5, 50, 0.1), Error);
}

TEST(SparseShapes, FindsTheExactRingShapeOfASymmetricTorusLikeMesh) {
  // Quads of a surface of revolution are isosceles trapezoids: translating one parallel
  // ring along the axis keeps every quad an affine image, a shape moving `around` vertices.
  const Index around = 12;
  const PolygonMesh mesh = generate::surfaceOfRevolution(around, 6);
  const ConstraintMatrix B = buildConstraintMatrix(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  const Index vertex = 3 * around + 5;  // An interior ring.
  SparseShapeInfo info;
  const Positions X = sparseShape(B, vertex, Eigen::Vector3d::UnitZ(), {}, &info);
  EXPECT_EQ(info.status, SparseShapeStatus::Exact);
  EXPECT_LE(info.residual, 1e-9);
  EXPECT_LE(info.supportVertices, 2 * around);
  EXPECT_LT(info.supportVertices, mesh.vertexCount() / 2);
  EXPECT_LE(B.residual(X), 1e-9 * X.norm());
  EXPECT_LE(maxPlanarity(mesh, mesh.vertices + 0.1 * X), 1e-9);
}

TEST(SparseShapes, ReportsAnApproximateShapeWithSmallResidualOnAPerturbedMesh) {
  // A flat quad grid jittered in its plane: polyhedral, with no symmetry left. Its affine
  // space holds its liftings (z), none of them supported near a single vertex.
  PolygonMesh mesh = generate::translationalSurface(10, 10);
  mesh.vertices = test::perturbed(mesh.vertices, 0.02);
  mesh.vertices.col(2).setZero();
  const ConstraintMatrix B = buildConstraintMatrix(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  SparseShapeSettings settings;
  settings.maxSupportVertices = 24;
  SparseShapeInfo info;
  const Positions X = sparseShape(B, 5 * 11 + 5, Eigen::Vector3d::UnitZ(), settings, &info);
  EXPECT_EQ(info.status, SparseShapeStatus::Approximate);
  EXPECT_GT(info.residual, 1e-9);
  EXPECT_LT(info.residual, 0.1 * info.initialResidual);
  EXPECT_LE(info.supportVertices, 24);
  EXPECT_NEAR(B.residual(X) / X.norm(), info.residual, 1e-12);
}

TEST(FundamentalShapes, MoveTheChosenVertexMostAndStayInTheSpace) {
  const PolygonMesh mesh = generate::translationalSurface(7, 7);
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Parallel, mesh.faceCount()));
  const compute::SparseMatrix L = uniformLaplacian(mesh.faces, mesh.vertexCount());
  const Index vertex = 4 * 8 + 3;
  const Positions X = fundamentalShape(space.N, L, vertex, Eigen::Vector3d::UnitZ());
  EXPECT_LE(space.B.residual(X), 1e-9 * X.norm());
  EXPECT_GT(X(vertex, 2), 0.0);
  // Optimality in the space: N^T ((X - delta) + lambda L^T L X) = 0.
  Positions delta = Positions::Zero(mesh.vertexCount(), 3);
  delta(vertex, 2) = 1.0;
  const Positions gradient = (X - delta) + Positions(L * Positions(L * X));
  EXPECT_LE(space.N.coefficients(gradient).norm(), 1e-9);
  // A smoother regularization spreads the motion: the vertex's share of the norm drops.
  FundamentalShapeSettings smooth;
  smooth.smoothness = 100.0;
  const Positions Y = fundamentalShape(space.N, L, vertex, Eigen::Vector3d::UnitZ(), smooth);
  EXPECT_LT(Y.row(vertex).norm() / Y.norm(), X.row(vertex).norm() / X.norm());
}

TEST(ConstrainedSubspace, ClosestMemberMeetsAHardConstraintTheSpaceAllows) {
  // Fig. 4: the closest member to a non-polyhedral mesh with one vertex held.
  const PolygonMesh cube = generate::cube();
  const LinearSpace space = buildLinearSpace(cube, uniformAssignment(SpaceKind::Affine, 6));
  const Positions noisy = test::perturbed(cube.vertices, 0.2);
  ASSERT_GT(maxPlanarity(cube, noisy), 1.0);
  PositionalConstraints constraints;
  constraints.handles.push_back({0, noisy.row(0).transpose()});
  const ConstrainedSubspace c = constrainSubspace(space.N, constraints, cube.vertices);
  const Positions X = closestInSubspace(space.N, c, noisy);
  EXPECT_LE(c.constraintResidual, 1e-12);
  EXPECT_LE((X.row(0) - noisy.row(0)).norm(), 1e-12);
  EXPECT_LE(maxPlanarity(cube, X), 1e-9);
  // Without the constraint the plain projection is closer overall, but misses vertex 0.
  const Positions P = space.N.project(noisy);
  EXPECT_LE((P - noisy).norm(), (X - noisy).norm() + 1e-12);
}

TEST(NonMaximalFaces, CubeInTheParallelSpaceIsReassignedToTheAffineSpace) {
  const PolygonMesh cube = generate::cube();
  const auto spaces = uniformAssignment(SpaceKind::Parallel, 6);
  const LinearSpace space = buildLinearSpace(cube, spaces);
  ASSERT_EQ(space.N.dimension(), 6);
  const auto faces = findNonMaximalFaces(space);
  ASSERT_EQ(faces.size(), 6u);
  for (const auto& f : faces) EXPECT_EQ(f.containedIn, FaceSpace::Affine);
  ReassignmentInfo info;
  const auto reassigned = reassignNonMaximalFaces(cube, spaces, {}, &info);
  EXPECT_EQ(info.dimensionBefore, 6);
  EXPECT_EQ(info.dimensionAfter, 12);
  EXPECT_EQ(info.reassignedFaces, 6);
  for (FaceSpace s : reassigned) EXPECT_EQ(s, FaceSpace::Affine);
}

TEST(NonMaximalFaces, AQuadGridInTheAffineSpaceIsAlreadyMaximal) {
  const PolygonMesh mesh = generate::translationalSurface(4, 4);
  ReassignmentInfo info;
  reassignNonMaximalFaces(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()), {}, &info);
  EXPECT_EQ(info.dimensionAfter, info.dimensionBefore);
  EXPECT_EQ(info.reassignedFaces, 0);
}

}  // namespace
}  // namespace plano::subspace
