// The host ADMM loop (compute/Admm.cpp's HostAdmmKernels) runs its vector work as row
// passes over C split across the CPU threads: its iterates must be those of the plain
// matrix expressions of OSQP's iteration, whatever the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "compute/Admm.h"
#include "compute/cpu/CpuBackend.h"
#include "core/ParallelFor.h"

namespace plano::test {
namespace {

struct Problem {
  compute::SparseMatrix P, C;
  Eigen::MatrixXd q, lower, upper;
};

/// Banded P (a shifted path Laplacian) and C (four entries a row, random values, about
/// diagonal), so that K factors quickly; every third row an equality, the others boxes
/// around a feasible point. Rows and unknowns enough for several threads' chunks.
Problem randomProblem(Index n, Index m, Index columns, unsigned seed) {
  Problem p;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (Index i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 3.0);
    if (i > 0) entries.emplace_back(i, i - 1, -1.0);
    if (i + 1 < n) entries.emplace_back(i, i + 1, -1.0);
  }
  p.P.resize(n, n);
  p.P.setFromTriplets(entries.begin(), entries.end());
  entries.clear();
  for (Index i = 0; i < m; ++i) {
    const Index first = std::min(i * n / m, n - 4);
    for (Index j = 0; j < 4; ++j) entries.emplace_back(i, first + j, uniform(random));
  }
  p.C.resize(m, n);
  p.C.setFromTriplets(entries.begin(), entries.end());
  p.C.makeCompressed();
  const Eigen::MatrixXd feasible = Eigen::MatrixXd::NullaryExpr(n, columns, [&] { return uniform(random); });
  p.q = Eigen::MatrixXd::NullaryExpr(n, columns, [&] { return 5.0 * uniform(random); });
  p.lower = p.C * feasible;
  p.upper = p.lower;
  for (Index i = 0; i < m; ++i) {
    if (i % 3 == 0) continue;
    for (Index c = 0; c < columns; ++c) {
      p.lower(i, c) -= 0.1 * (1.0 + uniform(random));
      p.upper(i, c) += 0.1 * (1.0 + uniform(random));
    }
  }
  return p;
}

/// One block of `iterations` ADMM iterations at the initial rho (no check in between).
compute::AdmmSettings oneBlock(int iterations) {
  compute::AdmmSettings settings;
  settings.maxIterations = iterations;
  settings.checkInterval = iterations;
  settings.adaptiveRho = false;
  settings.stallIterations = 0;
  return settings;
}

struct Iterate {
  Eigen::MatrixXd x, y, z;
  compute::AdmmInfo info;  ///< The host loop's: its residuals measured at the last check.
};

Iterate hostLoop(const Problem& p, const compute::AdmmSettings& settings, int threads) {
  setCpuThreads(threads);
  compute::CpuBackend cpu;
  auto solver = cpu.createAdmmSolver(p.P, p.C, settings);
  Iterate it;
  it.info = solver->solve(p.q, p.lower, p.upper, it.x, it.y, it.z);
  setCpuThreads(0);
  return it;
}

/// OSQP's iteration as matrix expressions, with the host loop's factorization of K.
Iterate matrixExpressions(const Problem& p, const compute::AdmmSettings& settings) {
  const Index n = p.P.rows(), m = p.C.rows(), k = p.q.cols();
  Eigen::VectorXd rho(m);
  for (Index i = 0; i < m; ++i) {
    const bool equality = (p.lower.row(i).array() == p.upper.row(i).array()).all();
    rho[i] = equality ? settings.rho * settings.equalityRhoScale : settings.rho;
  }
  const compute::SparseMatrix Ct = p.C.transpose();
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  const compute::SparseMatrix K = p.P + I * settings.sigma + compute::SparseMatrix(Ct * rho.asDiagonal() * p.C);
  compute::CpuBackend cpu;
  compute::LinearSolverSettings linear = settings.linearSolver;
  linear.measureResidual = false;
  auto solver = cpu.createSpdSolver(K, linear);
  const double alpha = settings.relaxation;
  Iterate it{Eigen::MatrixXd::Zero(n, k), Eigen::MatrixXd::Zero(m, k), Eigen::MatrixXd(), {}};
  it.z = (p.C * it.x).cwiseMax(p.lower).cwiseMin(p.upper);
  Eigen::MatrixXd xTilde = it.x;
  for (int i = 0; i < settings.maxIterations; ++i) {
    const Eigen::MatrixXd rhs = settings.sigma * it.x - p.q + Ct * (rho.asDiagonal() * it.z - it.y);
    solver->solve(rhs, xTilde);
    const Eigen::MatrixXd zTilde = p.C * xTilde;
    it.x = alpha * xTilde + (1.0 - alpha) * it.x;
    const Eigen::MatrixXd zRelaxed = alpha * zTilde + (1.0 - alpha) * it.z;
    const Eigen::MatrixXd zNext =
        (zRelaxed + rho.cwiseInverse().asDiagonal() * it.y).cwiseMax(p.lower).cwiseMin(p.upper);
    it.y += rho.asDiagonal() * (zRelaxed - zNext);
    it.z = zNext;
  }
  return it;
}

TEST(HostAdmm, IteratesAreTheMatrixExpressionsBitForBitOnOneAndSeveralThreads) {
  const compute::AdmmSettings settings = oneBlock(25);
  // Three columns (the global steps': one sweep over a row for all three) and two.
  for (const Index columns : {3, 2}) {
    SCOPED_TRACE(std::to_string(columns) + " columns");
    const Problem p = randomProblem(10000, 13000, columns, 7u + static_cast<unsigned>(columns));
    const Iterate reference = matrixExpressions(p, settings);
    ASSERT_TRUE(reference.x.allFinite());
    for (const int threads : {1, 3}) {
      SCOPED_TRACE(std::to_string(threads) + " threads");
      const Iterate host = hostLoop(p, settings, threads);
      EXPECT_TRUE(host.x == reference.x);
      EXPECT_TRUE(host.y == reference.y);
      EXPECT_TRUE(host.z == reference.z);
      // The check after the block measured the final iterate with its own row passes.
      EXPECT_EQ(host.info.primalResidual, (p.C * reference.x - reference.z).cwiseAbs().maxCoeff());
      EXPECT_EQ(host.info.dualResidual,
                (p.P * reference.x + p.q + compute::SparseMatrix(p.C.transpose()) * reference.y).cwiseAbs().maxCoeff());
    }
  }
}

}  // namespace
}  // namespace plano::test
