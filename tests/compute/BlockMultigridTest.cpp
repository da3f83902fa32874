// The aggregation V-cycle (host reference of the device preconditioner), plain and
// smoothed, against face-block Jacobi on the global step's real ADMM matrices: PCG
// iteration counts, symmetry of the cycle, and the aggregation itself.
#include "compute/BlockMultigrid.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <random>

#include "compute/GlobalStepMatrices.h"
#include "core/Error.h"

namespace plano::test {
namespace {

/// The ADMM matrix of a global step's exact attempt (GlobalStepMatrices.h).
compute::SparseMatrix globalStepMatrix(Index side, double rhoEquality) { return globalStepMatrices(side).K(rhoEquality); }

using Preconditioner = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

/// PCG iterations from zero to ||r|| <= 1e-10 ||b|| (-1: not within 20000).
int pcgIterations(const compute::SparseMatrix& K, const Eigen::VectorXd& b, const Preconditioner& M) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size()), r = b, z = M(r), p = z;
  double rz = r.dot(z);
  for (int iteration = 1; iteration <= 20000; ++iteration) {
    const Eigen::VectorXd q = K * p;
    const double step = rz / p.dot(q);
    x += step * p;
    r -= step * q;
    if (r.norm() <= 1e-10 * b.norm()) return iteration;
    z = M(r);
    const double next = r.dot(z);
    p = z + (next / rz) * p;
    rz = next;
  }
  return -1;
}

Preconditioner faceBlocks(const compute::SparseMatrix& K) {
  std::vector<Eigen::Matrix4d> inverses(K.rows() / 4);
  for (std::size_t f = 0; f < inverses.size(); ++f) {
    const auto first = static_cast<Eigen::Index>(4 * f);
    inverses[f] = Eigen::Matrix4d(Eigen::MatrixXd(K.block(first, first, 4, 4))).inverse();
  }
  return [inverses](const Eigen::VectorXd& r) {
    Eigen::VectorXd z(r.size());
    for (std::size_t f = 0; f < inverses.size(); ++f) z.segment<4>(4 * f) = inverses[f] * r.segment<4>(4 * f);
    return z;
  };
}

Eigen::VectorXd randomVector(Index n, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  return Eigen::VectorXd::NullaryExpr(n, [&] { return normal(random); });
}

TEST(BlockMultigrid, VCycleNeedsSeveralTimesFewerPcgIterationsThanFaceBlocksOnGlobalStepMatrices) {
  // Equality rows at rho * 10^3: rho 1 and 100 span the ADMM's usual range on these steps.
  // Measured (face blocks -> V-cycle): rho_eq 1e3: 229 -> 25 (1k faces), 347 -> 31 (4k);
  // rho_eq 1e5: 1514 -> 142, 1681 -> 114. Damping the smoother by 0.7 costs 5-10 % more.
  for (double rhoEquality : {1e3, 1e5}) {
    int previous = 0;
    for (Index side : {32, 64}) {
      SCOPED_TRACE(testing::Message() << "rho_eq " << rhoEquality << ", " << side * side << " faces");
      const compute::SparseMatrix K = globalStepMatrix(side, rhoEquality);
      const Eigen::VectorXd b = randomVector(K.rows(), 1);
      const compute::BlockMultigrid multigrid(K);
      const int blocks = pcgIterations(K, b, faceBlocks(K));
      const int cycles = pcgIterations(K, b, [&](const Eigen::VectorXd& r) { return multigrid.apply(r); });
      ASSERT_GT(blocks, 0);
      ASSERT_GT(cycles, 0);
      EXPECT_GE(blocks, 5 * cycles) << blocks << " face-block vs " << cycles << " V-cycle iterations";
      if (previous > 0) {
        EXPECT_LE(cycles, 2 * previous) << "grows slowly with the mesh";
      }
      previous = cycles;
    }
  }
}

TEST(BlockMultigrid, SmoothedAggregationKeepsPcgIterationsFlatAsTheMeshGrows) {
  // Measured (plain -> smoothed), rho_eq 1e3: 1k faces 25 -> 16, 4k 31 -> 14, 16k 45 -> 13.
  compute::BlockMultigridSettings smoothed;
  smoothed.smoothProlongation = true;
  int firstPlain = 0, firstSmoothed = 0;
  for (Index side : {32, 128}) {
    SCOPED_TRACE(testing::Message() << side * side << " faces");
    const compute::SparseMatrix K = globalStepMatrix(side, 1e3);
    const Eigen::VectorXd b = randomVector(K.rows(), 1);
    const compute::BlockMultigrid plainCycle(K), smoothedCycle(K, smoothed);
    ASSERT_EQ(smoothedCycle.levelCount(), plainCycle.levelCount()) << "the same aggregates";
    const int plain = pcgIterations(K, b, [&](const Eigen::VectorXd& r) { return plainCycle.apply(r); });
    const int flat = pcgIterations(K, b, [&](const Eigen::VectorXd& r) { return smoothedCycle.apply(r); });
    ASSERT_GT(plain, 0);
    ASSERT_GT(flat, 0);
    if (firstPlain == 0) {
      firstPlain = plain;
      firstSmoothed = flat;
      EXPECT_LT(flat, plain);
      continue;
    }
    EXPECT_GE(2 * plain, 3 * firstPlain) << "plain aggregation's iterations grow with the mesh";
    EXPECT_LE(flat, firstSmoothed + 2) << "smoothed aggregation's do not";
    EXPECT_GE(2 * plain, 5 * flat) << plain << " plain vs " << flat << " smoothed";
  }
}

TEST(BlockMultigrid, VCycleIsASymmetricPositiveOperator) {
  const compute::SparseMatrix K = globalStepMatrix(16, 1e4);
  for (bool smoothProlongation : {false, true}) {
    SCOPED_TRACE(smoothProlongation ? "smoothed aggregation" : "plain aggregation");
    compute::BlockMultigridSettings settings;
    settings.smoothProlongation = smoothProlongation;
    const compute::BlockMultigrid multigrid(K, settings);
    ASSERT_GE(multigrid.levelCount(), 3);
    const Eigen::VectorXd x = randomVector(K.rows(), 2), y = randomVector(K.rows(), 3);
    const double xMy = x.dot(multigrid.apply(y)), yMx = y.dot(multigrid.apply(x));
    EXPECT_NEAR(xMy, yMx, 1e-10 * std::abs(xMy));
    EXPECT_GT(x.dot(multigrid.apply(x)), 0.0);
  }
}

TEST(BlockMultigrid, SmoothedCycleStaysPositiveDefiniteAtStiffPenaltiesByDampingItsSmoother) {
  // The smoothed levels' lambda_max(D^-1 K) exceeds 2 at rho_eq 1e5 (2.38 on level 1 of this
  // grid): undamped block-Jacobi sweeps diverge on those modes and the symmetric cycle is
  // indefinite (M K's smallest eigenvalue -0.07), which stopped the device's PCG far from
  // the solution. Damped to smootherSpectralBound / lambda, M K's spectrum is [0.0073, 1].
  const compute::SparseMatrix K = globalStepMatrix(16, 1e5);
  const Eigen::MatrixXd dense(K);
  const Eigen::LLT<Eigen::MatrixXd> llt(dense);
  const Eigen::MatrixXd L = llt.matrixL();
  const auto smallestEigenvalueOfMK = [&](const compute::BlockMultigrid& cycle) {
    Eigen::MatrixXd M(K.rows(), K.rows());
    for (Eigen::Index i = 0; i < K.rows(); ++i) M.col(i) = cycle.apply(Eigen::VectorXd::Unit(K.rows(), i));
    // M K is similar to L^T M L (K = L L^T), symmetric where M is.
    const Eigen::MatrixXd similar = L.transpose() * ((M + M.transpose()) / 2) * L;
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(similar, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
  };
  compute::BlockMultigridSettings damped;
  damped.smoothProlongation = true;
  compute::BlockMultigridSettings undamped = damped;
  undamped.smootherSpectralBound = 1e9;  // damping min(1, bound / lambda) = 1
  EXPECT_GT(smallestEigenvalueOfMK(compute::BlockMultigrid(K, damped)), 1e-3);
  EXPECT_LT(smallestEigenvalueOfMK(compute::BlockMultigrid(K, undamped)), 0.0);
}

TEST(BlockMultigrid, SmoothedAggregationCoarseLevelsAreDenserThanPlainOnes) {
  // The price of the smoothed prolongation: 65k faces, operator complexity 2.3.
  const compute::SparseMatrix K = globalStepMatrix(32, 1e3);
  compute::BlockMultigridSettings smoothed;
  smoothed.smoothProlongation = true;
  const compute::BlockMultigrid plainCycle(K), smoothedCycle(K, smoothed);
  const auto complexity = [](const compute::BlockMultigrid& cycle) {
    double entries = 0.0;
    for (int l = 0; l < cycle.levelCount(); ++l) entries += static_cast<double>(cycle.nonZeros(l));
    return entries / static_cast<double>(cycle.nonZeros(0));
  };
  EXPECT_LT(complexity(plainCycle), 1.6);
  EXPECT_GT(complexity(smoothedCycle), complexity(plainCycle));
  EXPECT_LT(complexity(smoothedCycle), 3.0);
}

TEST(BlockMultigrid, LevelsShrinkAboutFourfoldWithAggregatesOfCoupledBlocks) {
  const compute::SparseMatrix K = globalStepMatrix(32, 1e4);
  const compute::BlockMultigrid multigrid(K);
  for (int l = 0; l + 1 < multigrid.levelCount(); ++l) {
    SCOPED_TRACE(l);
    const double ratio = static_cast<double>(multigrid.rows(l)) / static_cast<double>(multigrid.rows(l + 1));
    EXPECT_GT(ratio, 2.5);
    EXPECT_LE(ratio, 4.0);
    std::vector<int> size(multigrid.rows(l + 1) / 4, 0);
    for (Index a : multigrid.aggregates(l)) ++size[a];
    EXPECT_GT(*std::min_element(size.begin(), size.end()), 0) << "every coarse block has a fine block";
    EXPECT_LE(*std::max_element(size.begin(), size.end()), 4);
  }
  EXPECT_LE(multigrid.rows(multigrid.levelCount() - 1) / 4, 64);
}

TEST(BlockMultigrid, PairsAreCoupledBlocks) {
  const compute::SparseMatrix K = globalStepMatrix(8, 1e4);
  Index pairs = 0;
  const std::vector<Index> pair = compute::pairBlocks(K, 4, pairs);
  const Index blocks = K.rows() / 4;
  EXPECT_GE(pairs, blocks / 2);
  EXPECT_LT(pairs, blocks);
  for (Index i = 0; i < blocks; ++i) {
    for (Index j = i + 1; j < blocks; ++j) {
      if (pair[i] != pair[j]) continue;
      EXPECT_GT(Eigen::MatrixXd(K.block(4 * i, 4 * j, 4, 4)).norm(), 0.0) << "blocks " << i << " and " << j;
    }
  }
}

TEST(BlockMultigrid, BlockSizesThatDoNotDivideTheMatrixAreUsageErrors) {
  compute::SparseMatrix K(6, 6);
  K.setIdentity();
  try {
    compute::BlockMultigrid multigrid(K, {4});
    ADD_FAILURE() << "blocks of 4 accepted for 6 rows";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

}  // namespace
}  // namespace plano::test
