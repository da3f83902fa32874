// The device V-cycle (vk::Multigrid) against the host reference (compute::BlockMultigrid)
// on a global step's real ADMM matrix K = K0 + rho K1, with K's levels built the device's
// way (K0 and K1 coarsened separately, K_l assembled on the device, the coarsest inverted
// densely).
#include "compute/vulkan/VulkanMultigrid.h"

#include <gtest/gtest.h>

#include <random>
#include <utility>

#include "compute/GlobalStepMatrices.h"
#include "compute/VulkanFixture.h"
#include "core/Error.h"

namespace plano::test {
namespace {

class VulkanMultigrid : public VulkanTest {};

Eigen::MatrixXd randomColumns(Index n, Index m, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  return Eigen::MatrixXd::NullaryExpr(n, m, [&](Eigen::Index, Eigen::Index) { return normal(random); });
}

/// K0 = P + sigma I and K1 = C^T C on their union pattern, as the device ADMM keeps them.
std::pair<compute::SparseMatrix, compute::SparseMatrix> splitK(const GlobalStepMatrices& qp) {
  compute::SparseMatrix I(qp.P.rows(), qp.P.rows());
  I.setIdentity();
  const compute::SparseMatrix CtC = qp.C.transpose() * qp.C;
  compute::SparseMatrix K0 = qp.P + I * qp.sigma + CtC * 0.0;
  K0.makeCompressed();
  compute::SparseMatrix K1 = CtC + K0 * 0.0;
  K1.makeCompressed();
  return {K0, K1};
}

/// The device cycle z = M r for K = K0 + rho K1 (K0 = P + sigma I and K1 = C^T C on their
/// union pattern), level 0's K and block inverses uploaded as the ADMM computes them.
Eigen::MatrixXd deviceCycle(vk::Context& context, const compute::BlockAggregation& aggregation,
                            const compute::SparseMatrix& K0, const compute::SparseMatrix& K1, double rho,
                            const Eigen::MatrixXd& r, int* levels = nullptr, bool smoothed = false) {
  vk::LinearAlgebra algebra(context);
  vk::Multigrid multigrid(context, algebra, aggregation, K0, K0, smoothed);
  multigrid.setK1(K1);
  if (levels) *levels = multigrid.levelCount();
  compute::SparseMatrix K = K0 + K1 * rho;
  K.makeCompressed();
  vk::DeviceCsrMatrix deviceK(context, K);
  vk::Array<double> inverses(context, static_cast<std::size_t>(K.rows()) * 4, vk::MemoryClass::Device, "inverses");
  vk::Array<std::uint32_t> failure(context, 1, vk::MemoryClass::Host, "failure");
  const std::uint32_t none = ~0u;
  failure.upload({&none, 1});
  vk::DeviceVectors input(context, static_cast<std::uint32_t>(r.rows()), static_cast<std::uint32_t>(r.cols()), "r");
  vk::DeviceVectors output(context, input.n(), input.m(), "z");
  input.upload(r);
  vk::Sequence s(context);
  s.begin();
  algebra.invertDiagonalBlocks(s, deviceK, 4, inverses, failure);
  multigrid.setRho(s, rho, deviceK, inverses, failure);
  const auto binding = multigrid.bind(deviceK, inverses, input, output);
  multigrid.record(s, *binding, nullptr, 0);
  s.end();
  s.run();
  std::uint32_t failed = 0;
  failure.download({&failed, 1});
  EXPECT_EQ(failed, ~0u);
  Eigen::MatrixXd z;
  output.download(z);
  return z;
}

TEST_F(VulkanMultigrid, CycleEqualsTheHostReferenceOnAGlobalStepMatrix) {
  const auto [K0, K1] = splitK(globalStepMatrices(24));  // 576 faces: three levels
  const compute::BlockAggregation aggregation(compute::SparseMatrix(K0 + K1), {4});
  ASSERT_GE(aggregation.levelCount(), 3);
  // Three columns (a global step's) at two penalties, and five: the fused products take
  // four columns an invocation, then the fifth.
  for (const auto& [rho, columns] : {std::pair{1e2, 3}, std::pair{1e5, 3}, std::pair{1e3, 5}}) {
    SCOPED_TRACE(testing::Message() << "rho " << rho << ", " << columns << " columns");
    const Eigen::MatrixXd r = randomColumns(K0.rows(), columns, 7);
    int levels = 0;
    const Eigen::MatrixXd device = deviceCycle(context(), aggregation, K0, K1, rho, r, &levels);
    EXPECT_EQ(levels, aggregation.levelCount());
    compute::SparseMatrix K = K0 + K1 * rho;
    K.makeCompressed();
    const compute::BlockMultigrid host(aggregation, aggregation.coarsen(K));
    for (Eigen::Index c = 0; c < r.cols(); ++c) {
      const Eigen::VectorXd expected = host.apply(r.col(c));
      EXPECT_LT((device.col(c) - expected).norm() / expected.norm(), 1e-9) << "column " << c;
    }
  }
}

TEST_F(VulkanMultigrid, SmoothedCycleEqualsTheHostReferenceOnAGlobalStepMatrix) {
  const auto [K0, K1] = splitK(globalStepMatrices(24));  // 576 faces: three levels
  const compute::BlockAggregation aggregation(compute::SparseMatrix(K0 + K1), {4});
  ASSERT_GE(aggregation.levelCount(), 3);
  for (const auto& [rho, columns] : {std::pair{1e2, 3}, std::pair{1e5, 3}, std::pair{1e3, 5}}) {
    SCOPED_TRACE(testing::Message() << "rho " << rho << ", " << columns << " columns");
    const Eigen::MatrixXd r = randomColumns(K0.rows(), columns, 11);
    const Eigen::MatrixXd device = deviceCycle(context(), aggregation, K0, K1, rho, r, nullptr, true);
    compute::SparseMatrix K = K0 + K1 * rho;
    K.makeCompressed();
    compute::BlockMultigridSettings smoothed{4};
    smoothed.smoothProlongation = true;
    const compute::BlockMultigrid host(aggregation, K, smoothed);
    const compute::BlockMultigrid plain(aggregation, aggregation.coarsen(K));
    for (Eigen::Index c = 0; c < r.cols(); ++c) {
      const Eigen::VectorXd expected = host.apply(r.col(c));
      EXPECT_LT((device.col(c) - expected).norm() / expected.norm(), 1e-9) << "column " << c;
      // Not the plain cycle: the coarse levels are P^T K P.
      EXPECT_GT((device.col(c) - plain.apply(r.col(c))).norm() / expected.norm(), 1e-3) << "column " << c;
    }
  }
}

TEST_F(VulkanMultigrid, SmoothedCycleOfAKWithPartialBlocksEqualsTheHostReference) {
  // The products of the smoothed cycle run over whole 4x4 blocks; a K whose pattern leaves
  // out entries of its blocks is copied onto its block-complete pattern first. This K: the
  // global step's, its entries (4i, 4j + 1) between different faces removed, and the rows'
  // diagonals raised by what they lost (still positive definite: K - E + |E|'s row sums).
  const auto [K0, K1] = splitK(globalStepMatrices(16));
  compute::SparseMatrix K = K0 + K1 * 1e3;
  K.makeCompressed();
  std::vector<Eigen::Triplet<double>> kept;
  Eigen::VectorXd lost = Eigen::VectorXd::Zero(K.rows());
  for (Index r = 0; r < K.rows(); ++r) {
    for (compute::SparseMatrix::InnerIterator it(K, r); it; ++it) {
      const Index c = it.col();
      const bool removed = r / 4 != c / 4 && ((r % 4 == 0 && c % 4 == 1) || (r % 4 == 1 && c % 4 == 0));
      if (removed) {
        lost[r] += std::abs(it.value());
      } else {
        kept.emplace_back(r, c, it.value());
      }
    }
  }
  for (Index r = 0; r < K.rows(); ++r) kept.emplace_back(r, r, lost[r]);
  compute::SparseMatrix partial(K.rows(), K.cols());
  partial.setFromTriplets(kept.begin(), kept.end());
  partial.makeCompressed();
  ASSERT_LT(partial.nonZeros(), K.nonZeros());
  const compute::SparseMatrix zero = partial * 0.0;
  const compute::BlockAggregation aggregation(partial, {4});
  ASSERT_GE(aggregation.levelCount(), 2);
  const Eigen::MatrixXd r = randomColumns(K.rows(), 3, 12);
  const Eigen::MatrixXd device = deviceCycle(context(), aggregation, partial, zero, 1.0, r, nullptr, true);
  compute::BlockMultigridSettings smoothed{4};
  smoothed.smoothProlongation = true;
  const compute::BlockMultigrid host(aggregation, partial, smoothed);
  for (Eigen::Index c = 0; c < r.cols(); ++c) {
    const Eigen::VectorXd expected = host.apply(r.col(c));
    EXPECT_LT((device.col(c) - expected).norm() / expected.norm(), 1e-9) << "column " << c;
  }
}

TEST_F(VulkanMultigrid, OneLevelIsTheExactInverse) {
  const auto [K0, K1] = splitK(globalStepMatrices(4));  // 16 faces: below the coarsest size
  const compute::BlockAggregation aggregation(compute::SparseMatrix(K0 + K1), {4});
  ASSERT_EQ(aggregation.levelCount(), 1);
  const Eigen::MatrixXd r = randomColumns(K0.rows(), 2, 8);
  const Eigen::MatrixXd z = deviceCycle(context(), aggregation, K0, K1, 1e3, r);
  const compute::SparseMatrix K = K0 + K1 * 1e3;
  EXPECT_LT((K * z - r).norm() / r.norm(), 1e-10);
}

TEST_F(VulkanMultigrid, ACoarsestLevelSplitAcrossDispatchesIsInvertedOnTheDeviceExactly) {
  // 64 faces, all 64 blocks (256 rows) on one level: its elimination runs one dispatch per
  // step, each step's rows dealt out among workgroups (one per core on a CPU device), and
  // each step defers its pivot's row and column to the next.
  const auto [K0, K1] = splitK(globalStepMatrices(8));
  compute::BlockMultigridSettings settings{4};
  settings.coarsestBlocks = 64;
  const compute::BlockAggregation aggregation(compute::SparseMatrix(K0 + K1), settings);
  ASSERT_EQ(aggregation.levelCount(), 1);
  ASSERT_EQ(K0.rows(), 256);
  const Eigen::MatrixXd r = randomColumns(K0.rows(), 2, 9);
  for (double rho : {1e-1, 1e3}) {
    SCOPED_TRACE(rho);
    const Eigen::MatrixXd z = deviceCycle(context(), aggregation, K0, K1, rho, r);
    const compute::SparseMatrix K = K0 + K1 * rho;
    EXPECT_LT((K * z - r).norm() / r.norm(), 1e-10);
  }
}

TEST_F(VulkanMultigrid, ACoarsestLevelThatIsNotPositiveDefiniteLeavesItsFailureCode) {
  const auto [K0, K1] = splitK(globalStepMatrices(4));
  const compute::BlockAggregation aggregation(compute::SparseMatrix(K0 + K1), {4});
  vk::LinearAlgebra algebra(context());
  vk::Multigrid multigrid(context(), algebra, aggregation, K0, K0);
  multigrid.setK1(K1);
  vk::Array<std::uint32_t> failure(context(), 1, vk::MemoryClass::Host, "failure");
  for (const auto& [rho, expected] : {std::pair{1e3, ~0u}, std::pair{-1e3, vk::Multigrid::kCoarsestFailure}}) {
    SCOPED_TRACE(rho);
    const std::uint32_t none = ~0u;
    failure.upload({&none, 1});
    vk::Sequence s(context());
    s.begin();
    multigrid.setRho(s, rho, failure);
    s.end();
    s.run();
    std::uint32_t failed = 0;
    failure.download({&failed, 1});
    EXPECT_EQ(failed, expected);
  }
}

}  // namespace
}  // namespace plano::test
