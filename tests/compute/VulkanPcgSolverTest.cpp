// The device PCG solver against CHOLMOD on Laplacian-like SPD systems from meshes.
#include "compute/vulkan/VulkanPcgSolver.h"

#include <gtest/gtest.h>

#include "compute/GlobalStepMatrices.h"
#include "compute/MeshMatrices.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"

namespace plano::test {
namespace {

class VulkanPcgSolver : public VulkanTest {};

Eigen::MatrixXd rightHandSides(const PolygonMesh& mesh) {
  // Like a global step: the coordinates themselves plus a smooth bump.
  Eigen::MatrixXd B = mesh.vertices;
  B.col(2) += mesh.vertices.col(0).array().sin().matrix();
  return B;
}

TEST_F(VulkanPcgSolver, MatchesCholmodToTheRequestedTolerance) {
  const PolygonMesh mesh = generate::translationalSurface(40, 40);
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 0.01);
  const Eigen::MatrixXd B = rightHandSides(mesh);
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-10;
  auto pcg = backend().createSpdSolver(A, settings);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(B.rows(), B.cols());
  const compute::LinearSolveInfo info = pcg->solve(B, X);
  EXPECT_TRUE(info.converged);
  EXPECT_GT(info.iterations, 0);
  EXPECT_LE(info.relativeResidual, 1e-10 * 1.5);  // recursive vs true residual
  EXPECT_LE((A * X - B).norm() / B.norm(), 1.5e-10);

  auto cholmod = compute::CpuBackend().createSpdSolver(A, settings);
  Eigen::MatrixXd reference;
  cholmod->solve(B, reference);
  // Error bound from the residual: ||x - x*|| <= ||A^-1|| ||r|| <= ||r|| / lambda_min.
  EXPECT_LT((X - reference).norm() / reference.norm(), 1e-6);
}

TEST_F(VulkanPcgSolver, SolvesSixRightHandSidesEachToTheTolerance) {
  // Each column has its own step lengths and stopping test.
  const PolygonMesh mesh = generate::translationalSurface(20, 20);
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 0.01);
  Eigen::MatrixXd B(mesh.vertexCount(), 6);
  B << rightHandSides(mesh), mesh.vertices.array().cos().matrix();
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-10;
  auto pcg = backend().createSpdSolver(A, settings);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(B.rows(), B.cols());
  EXPECT_TRUE(pcg->solve(B, X).converged);
  for (Eigen::Index c = 0; c < B.cols(); ++c) {
    EXPECT_LE((A * X.col(c) - B.col(c)).norm() / B.col(c).norm(), 1.5e-10) << "column " << c;
  }
}

TEST_F(VulkanPcgSolver, WarmStartFromTheSolutionNeedsNoIterations) {
  const PolygonMesh mesh = generate::hexagonalDome(6);
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 0.1);
  const Eigen::MatrixXd B = rightHandSides(mesh);
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-8;
  auto pcg = backend().createSpdSolver(A, settings);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(B.rows(), 3);
  const compute::LinearSolveInfo cold = pcg->solve(B, X);
  ASSERT_TRUE(cold.converged);
  const compute::LinearSolveInfo warm = pcg->solve(B, X);
  EXPECT_TRUE(warm.converged);
  EXPECT_EQ(warm.iterations, 0);
  EXPECT_LT(warm.relativeResidual, 1e-8);
}

TEST_F(VulkanPcgSolver, LooserToleranceTakesFewerIterations) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(40, 20);
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 0.01);
  const Eigen::MatrixXd B = rightHandSides(mesh);
  compute::LinearSolverSettings loose, tight;
  loose.relativeTolerance = 1e-4;
  tight.relativeTolerance = 1e-11;
  Eigen::MatrixXd X1 = Eigen::MatrixXd::Zero(B.rows(), 3), X2 = X1;
  const auto a = backend().createSpdSolver(A, loose)->solve(B, X1);
  const auto b = backend().createSpdSolver(A, tight)->solve(B, X2);
  EXPECT_TRUE(a.converged && b.converged);
  EXPECT_LT(a.iterations, b.iterations);
  EXPECT_LE(a.relativeResidual, 1.5e-4);
  EXPECT_LE(b.relativeResidual, 1.5e-11);
}

TEST_F(VulkanPcgSolver, IterationCapIsReportedAsNotConverged) {
  const PolygonMesh mesh = generate::translationalSurface(30, 30);
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 1e-4);
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-12;
  settings.maxIterations = 16;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(A.rows(), 3);
  const auto info = backend().createSpdSolver(A, settings)->solve(rightHandSides(mesh), X);
  EXPECT_FALSE(info.converged);
  EXPECT_EQ(info.iterations, 16);
  EXPECT_GT(info.relativeResidual, 1e-12);
}

TEST_F(VulkanPcgSolver, NonPositiveDiagonalIsANumericalErrorNamingTheRow) {
  compute::SparseMatrix A(3, 3);
  A.insert(0, 0) = 1.0;
  A.insert(1, 1) = -2.0;
  A.insert(2, 2) = 1.0;
  A.makeCompressed();
  try {
    backend().createSpdSolver(A, {});
    FAIL() << "expected Error(Numerical)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("row 1"), std::string::npos) << e.what();
  }
}

TEST_F(VulkanPcgSolver, FaceBlocksSolveAGlobalStepSystemInFewerIterationsThanJacobi) {
  // The polish's kind of system: every row of a global step's C active, stiff. Its
  // 4x4 blocks (one face's map entries) are strongly coupled.
  const GlobalStepMatrices matrices = globalStepMatrices(6);
  const compute::SparseMatrix K = matrices.K(1e3);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(K.rows(), 3);
  for (Eigen::Index i = 0; i < K.rows(); ++i) B(i, i % 3) = 1.0 + 0.01 * static_cast<double>(i % 7);
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-10;
  settings.maxIterations = 20000;
  Eigen::MatrixXd jacobiX = Eigen::MatrixXd::Zero(K.rows(), 3);
  const auto jacobi = backend().createSpdSolver(K, settings)->solve(B, jacobiX);
  settings.preconditionerBlock = 4;
  Eigen::MatrixXd blockX = Eigen::MatrixXd::Zero(K.rows(), 3);
  const auto blocks = backend().createSpdSolver(K, settings)->solve(B, blockX);
  ASSERT_TRUE(jacobi.converged);
  ASSERT_TRUE(blocks.converged);
  EXPECT_LT(2 * blocks.iterations, jacobi.iterations) << blocks.iterations << " vs " << jacobi.iterations;

  Eigen::MatrixXd reference;
  compute::CpuBackend().createSpdSolver(K, {})->solve(B, reference);
  EXPECT_LT((blockX - reference).norm() / reference.norm(), 1e-7);
  EXPECT_LE((K * blockX - B).norm() / B.norm(), 1.5e-10);
}

TEST_F(VulkanPcgSolver, ABlockThatIsNotPositiveDefiniteIsANumericalErrorNamingItsRows) {
  compute::SparseMatrix A(8, 8);
  for (int i = 0; i < 8; ++i) A.insert(i, i) = 1.0;
  A.coeffRef(4, 5) = 2.0;  // rows 4..7: [[1, 2], [2, 1]] is indefinite
  A.coeffRef(5, 4) = 2.0;
  A.makeCompressed();
  compute::LinearSolverSettings settings;
  settings.preconditionerBlock = 4;
  try {
    backend().createSpdSolver(A, settings);
    FAIL() << "expected Error(Numerical)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("rows 4 to 7"), std::string::npos) << e.what();
  }
  settings.preconditionerBlock = 3;  // does not divide 8
  EXPECT_THROW(backend().createSpdSolver(A, settings), Error);
}

}  // namespace
}  // namespace plano::test
