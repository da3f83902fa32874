// Handle-based ASAP/ARAP deformation inside linear spaces (linear-spaces paper, Fig. 8).
#include <gtest/gtest.h>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "subspace/SubspaceDeformation.h"
#include "subspace/SubspaceTestSupport.h"
#include "subspace/SubspaceTopology.h"

namespace plano::subspace {
namespace {

using test::maxPlanarity;

/// Boundary fixed, the vertex nearest the top raised by `lift` along z.
PositionalConstraints domeConstraints(const PolygonMesh& mesh, double lift, Index* top) {
  const SubspaceTopology t = computeTopology(mesh.faces, mesh.vertexCount());
  PositionalConstraints c;
  for (const auto& loop : t.boundaryLoops) c.fixed.insert(c.fixed.end(), loop.begin(), loop.end());
  mesh.vertices.col(2).maxCoeff(top);
  c.handles.push_back({*top, mesh.vertices.row(*top).transpose() + Eigen::Vector3d(0, 0, lift)});
  return c;
}

TEST(SubspaceDeformation, VerticalSpaceOfAHexDomeStaysPolyhedralEveryIterateAndReachesTheHandle) {
  const PolygonMesh mesh = generate::hexagonalDome(3);
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Vertical, mesh.faceCount()));
  Index top = 0;
  const double lift = 0.05 * boundingBoxDiagonal(mesh.vertices);
  const PositionalConstraints constraints = domeConstraints(mesh, lift, &top);
  compute::CpuBackend backend;
  SubspaceDeformationSettings settings;
  settings.maxIterations = 30;
  SubspaceDeformer deformer(space, constraints, backend, settings);
  Positions X = mesh.vertices;
  double worst = 0.0;
  Index calls = 0;
  const auto info = deformer.solve(X, [&](Index, const Positions& iterate) {
    worst = std::max(worst, maxPlanarity(mesh, iterate));
    ++calls;
  });
  EXPECT_EQ(calls, info.iterations);
  EXPECT_GT(info.iterations, 0);
  EXPECT_LE(worst, 1e-9);
  EXPECT_LE(info.maxSubspaceResidual, 1e-9);
  // The handle rises as far as the space allows: its position is the least-squares
  // solution of the constraints over the space, which keeps the fixed boundary.
  const double risen = X(top, 2) - mesh.vertices(top, 2);
  EXPECT_GT(risen, 0.25 * lift) << "constraint residual " << info.constraintResidual;
  EXPECT_LE(info.maxHandleDistance, lift);
}

TEST(SubspaceDeformation, AffineSpaceOfAClosedThreeRegularMeshOnlyMovesGlobally) {
  const PolygonMesh mesh = generate::dodecahedron();
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  ASSERT_EQ(space.N.dimension(), 12);
  PositionalConstraints constraints;
  constraints.fixed = {0, 1, 2};
  constraints.handles.push_back({10, mesh.vertices.row(10).transpose() + Eigen::Vector3d(0.3, -0.2, 0.4)});
  compute::CpuBackend backend;
  SubspaceDeformer deformer(space, constraints, backend);
  Positions X = mesh.vertices;
  const auto info = deformer.solve(X);
  EXPECT_LE(maxPlanarity(mesh, X), 1e-9);
  // X = A Y + t: an affine map of the whole mesh fits every vertex.
  Eigen::MatrixXd Yh(mesh.vertexCount(), 4);
  Yh << mesh.vertices, Eigen::VectorXd::Ones(mesh.vertexCount());
  const Eigen::MatrixXd map = Yh.colPivHouseholderQr().solve(Eigen::MatrixXd(X));
  EXPECT_LE((Yh * map - X).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GT((X - mesh.vertices).norm(), 1e-3);  // It did move (the handle pulls).
  (void)info;
}

TEST(SubspaceDeformation, AffineSpaceOfAHexDomeCannotReachTheHandleButStaysPolyhedral) {
  const PolygonMesh mesh = generate::hexagonalDome(3);
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Affine, mesh.faceCount()));
  Index top = 0;
  const double lift = 0.05 * boundingBoxDiagonal(mesh.vertices);
  const PositionalConstraints constraints = domeConstraints(mesh, lift, &top);
  compute::CpuBackend backend;
  SubspaceDeformationSettings settings;
  settings.energy = DeformationEnergy::Arap;
  SubspaceDeformer deformer(space, constraints, backend, settings);
  Positions X = mesh.vertices;
  const auto info = deformer.solve(X);
  EXPECT_GT(info.constraintResidual, 1e-6 * lift);  // As far as the space allows, not further.
  EXPECT_LT(X(top, 2) - mesh.vertices(top, 2), lift);
  EXPECT_LE(maxPlanarity(mesh, X), 1e-9);
}

TEST(SubspaceDeformation, ConstraintOutOfRangeIsReportedByVertex) {
  const PolygonMesh mesh = generate::cube();
  const LinearSpace space = buildLinearSpace(mesh, uniformAssignment(SpaceKind::Parallel, 6));
  PositionalConstraints constraints;
  constraints.fixed = {42};
  compute::CpuBackend backend;
  try {
    SubspaceDeformer deformer(space, constraints, backend);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("42"), std::string::npos);
  }
}

}  // namespace
}  // namespace plano::subspace
