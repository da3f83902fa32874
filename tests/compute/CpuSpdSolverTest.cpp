// The CPU backend's prefactored Cholesky (CHOLMOD).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "compute/MeshMatrices.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"

namespace plano::test {
namespace {

struct System {
  compute::SparseMatrix A;
  Eigen::MatrixXd B;
};

System meshSystem() {
  const PolygonMesh mesh = generate::translationalSurface(12, 12);
  return {laplacianLikeSpd(mesh, 0.01), mesh.vertices};
}

TEST(CpuSpdSolver, MeasuresTheRelativeResidualByDefault) {
  const System s = meshSystem();
  auto solver = compute::CpuBackend().createSpdSolver(s.A, {});
  Eigen::MatrixXd X;
  const compute::LinearSolveInfo info = solver->solve(s.B, X);
  EXPECT_TRUE(info.converged);
  EXPECT_EQ(info.iterations, 1);
  EXPECT_GT(info.relativeResidual, 0.0);  // rounding, measured
  EXPECT_LT(info.relativeResidual, 1e-12);
}

TEST(CpuSpdSolver, WithoutTheResidualItGivesTheSameSolutionAndStillFlagsNonFiniteOnes) {
  const System s = meshSystem();
  compute::CpuBackend cpu;
  auto measured = cpu.createSpdSolver(s.A, {});
  compute::LinearSolverSettings settings;
  settings.measureResidual = false;
  auto unmeasured = cpu.createSpdSolver(s.A, settings);
  Eigen::MatrixXd X, Y;
  measured->solve(s.B, X);
  const compute::LinearSolveInfo info = unmeasured->solve(s.B, Y);
  EXPECT_TRUE(info.converged);
  EXPECT_EQ(info.relativeResidual, 0.0);
  EXPECT_EQ(X, Y);

  Eigen::MatrixXd bad = s.B;
  bad(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(unmeasured->solve(bad, Y).converged);
  EXPECT_FALSE(measured->solve(bad, X).converged);
}

/// A dense SPD matrix stored sparse: CHOLMOD factors it supernodally (about 2n/3 flops per
/// entry of L), where the mesh matrices of meshSystem() get a simplicial factor.
compute::SparseMatrix denseSpd(Eigen::Index n) {
  const Eigen::MatrixXd M = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd A = M * M.transpose() + static_cast<double>(n) * Eigen::MatrixXd::Identity(n, n);
  return A.sparseView();
}

TEST(CpuSpdSolver, SolvesToRoundingAndRefusesIndefiniteMatricesWithSimplicialAndSupernodalFactors) {
  compute::CpuBackend cpu;
  const System mesh = meshSystem();
  const compute::SparseMatrix dense = denseSpd(400);
  for (const compute::SparseMatrix* A : {&mesh.A, &dense}) {
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(A->rows(), 3);
    auto solver = cpu.createSpdSolver(*A, {});
    Eigen::MatrixXd X;
    const compute::LinearSolveInfo info = solver->solve(B, X);
    EXPECT_TRUE(info.converged);
    EXPECT_LT(info.relativeResidual, 1e-12) << A->rows() << " rows";
    EXPECT_LT((Eigen::MatrixXd(*A) * X - B).norm(), 1e-12 * B.norm()) << A->rows() << " rows";

    // One pivot far below zero: no Cholesky factor exists, whichever kind was chosen.
    compute::SparseMatrix indefinite = *A;
    indefinite.coeffRef(A->rows() / 2, A->rows() / 2) = -1e3 * std::abs(A->coeff(0, 0));
    EXPECT_THROW(cpu.createSpdSolver(indefinite, {}), Error) << A->rows() << " rows";
    try {
      solver->refactor(indefinite);
      ADD_FAILURE() << "refactored an indefinite matrix, " << A->rows() << " rows";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    }
    // A solver whose refactorization failed has no factor to solve with.
    EXPECT_FALSE(solver->solve(B, X).converged) << A->rows() << " rows";
  }
}

TEST(CpuSpdSolver, AFactorLargerThanItsMemoryLimitIsRefusedNamingItsMatrixBeforeItIsComputed) {
  const System s = meshSystem();
  const Eigen::Index n = s.A.rows();
  // L holds at least A's lower triangle, at most a dense triangle (plus CHOLMOD's
  // largest update matrix, at most n x n): the estimate lies between.
  const compute::SparseMatrix lower = s.A.triangularView<Eigen::Lower>();
  compute::LinearSolverSettings settings;
  settings.memoryLimitBytes = static_cast<std::uint64_t>(lower.nonZeros()) * sizeof(double) - 1;
  compute::CpuBackend cpu;
  try {
    cpu.createSpdSolver(s.A, settings);
    ADD_FAILURE() << "no error";
  } catch (const OutOfMemory& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    const std::string message = e.what();
    EXPECT_NE(message.find("the Cholesky factor of a sparse " + std::to_string(n) + " x " + std::to_string(n) +
                           " matrix (" + std::to_string(s.A.nonZeros()) + " nonzeros)"),
              std::string::npos)
        << message;
  }
  settings.memoryLimitBytes = static_cast<std::uint64_t>(2 * n * n) * sizeof(double);
  auto solver = cpu.createSpdSolver(s.A, settings);
  Eigen::MatrixXd X;
  EXPECT_TRUE(solver->solve(s.B, X).converged);
}

}  // namespace
}  // namespace plano::test
