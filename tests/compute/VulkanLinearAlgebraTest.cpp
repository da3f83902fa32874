// Device linear algebra against Eigen: SpMV, dot, axpby, row scaling, box projection, value
// gathers and the block-Jacobi inverses to 1e-12 relative.
#include "compute/vulkan/VulkanLinearAlgebra.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "compute/MeshMatrices.h"
#include "compute/VulkanFixture.h"
#include "core/Error.h"

namespace plano::test {
namespace {

Eigen::MatrixXd randomBlock(Index n, Index m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Eigen::MatrixXd::NullaryExpr(n, m, [&](Eigen::Index, Eigen::Index) { return u(rng); });
}

double relativeError(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  return (actual - expected).norm() / expected.norm();
}

class VulkanLinearAlgebra : public VulkanTest {
 protected:
  static void TearDownTestSuite() { algebra_.reset(); }
  vk::LinearAlgebra& algebra() {
    if (!algebra_) algebra_ = std::make_unique<vk::LinearAlgebra>(context());
    return *algebra_;
  }
  vk::DeviceVectors vectors(const Eigen::MatrixXd& values, const char* what = "test vectors") {
    vk::DeviceVectors v(context(), static_cast<std::uint32_t>(values.rows()),
                        static_cast<std::uint32_t>(values.cols()), what);
    v.upload(values);
    return v;
  }
  static inline std::unique_ptr<vk::LinearAlgebra> algebra_;
};

TEST_F(VulkanLinearAlgebra, SpmvMatchesEigenOnRectangularMatrixAndSeveralColumns) {
  // Each invocation takes a row for up to four columns (shaders/csr_rows.glsl): every width
  // of a chunk, and more columns than one chunk holds.
  const compute::SparseMatrix A = randomSparse(3000, 2000, 7, 1);
  vk::DeviceCsrMatrix deviceA(context(), A);
  for (Index columns : {1, 2, 3, 4, 5, 9}) {
    SCOPED_TRACE(columns);
    const Eigen::MatrixXd X = randomBlock(2000, columns, 2);
    vk::DeviceVectors x = vectors(X);
    vk::DeviceVectors y(context(), 3000, static_cast<std::uint32_t>(columns), "y");
    vk::Sequence s(context());
    s.begin();
    algebra().spmv(s, deviceA, x, y);
    s.end();
    s.run();
    Eigen::MatrixXd Y;
    y.download(Y);
    EXPECT_LT(relativeError(Y, A * X), 1e-12);
  }
}

TEST_F(VulkanLinearAlgebra, DotProductsMatchEigenPerColumnForManySizes) {
  for (Index n : {1, 63, 64, 1000, 100000}) {
    const Eigen::MatrixXd X = randomBlock(n, 3, 3), Y = randomBlock(n, 3, 4);
    vk::DeviceVectors x = vectors(X), y = vectors(Y);
    vk::DeviceScalars scalars(context(), 2, 3, static_cast<std::uint32_t>(n));
    vk::Sequence s(context());
    s.begin();
    algebra().dot(s, x, y, scalars, 1);
    algebra().dot(s, x, x, scalars, 0);
    s.end();
    s.run();
    const std::vector<double> values = scalars.read();
    for (std::uint32_t c = 0; c < 3; ++c) {
      const double expected = X.col(c).dot(Y.col(c));
      EXPECT_NEAR(scalars.at(values, 1, c), expected, 1e-12 * X.col(c).norm() * Y.col(c).norm()) << "n " << n;
      EXPECT_NEAR(scalars.at(values, 0, c), X.col(c).squaredNorm(), 1e-12 * X.col(c).squaredNorm()) << "n " << n;
    }
  }
}

TEST_F(VulkanLinearAlgebra, BlockDiagonalProductMatchesEigenForEveryBlockSize) {
  const Eigen::MatrixXd X = randomBlock(1200, 3, 8);
  for (std::uint32_t b = 1; b <= 4; ++b) {
    SCOPED_TRACE(b);
    const Eigen::MatrixXd entries = randomBlock(1200, b, 9 + b);  // row r: block r / b's row r % b
    Eigen::MatrixXd expected(1200, 3);
    for (Index first = 0; first < 1200; first += b) {
      expected.middleRows(first, b) = entries.middleRows(first, b) * X.middleRows(first, b);
    }
    std::vector<double> blocks(1200 * b);
    for (Index r = 0; r < 1200; ++r) {
      for (std::uint32_t c = 0; c < b; ++c) blocks[r * b + c] = entries(r, c);
    }
    vk::Array<double> deviceBlocks(context(), blocks.size(), vk::MemoryClass::Device, "blocks");
    deviceBlocks.upload(blocks);
    vk::DeviceVectors x = vectors(X), y(context(), 1200, 3, "y");
    vk::Sequence s(context());
    s.begin();
    algebra().applyBlockDiagonal(s, deviceBlocks, b, x, y);
    s.end();
    s.run();
    Eigen::MatrixXd Y;
    y.download(Y);
    EXPECT_LT(relativeError(Y, expected), 1e-12);
  }
}

/// The device's inverse diagonal blocks and the failing block (~0u: none).
std::pair<std::vector<double>, std::uint32_t> invertBlocksOnDevice(vk::Context& context, vk::LinearAlgebra& algebra,
                                                                   const compute::SparseMatrix& A, std::uint32_t b) {
  vk::DeviceCsrMatrix deviceA(context, A);
  vk::Array<double> inverses(context, static_cast<std::size_t>(A.rows()) * b, vk::MemoryClass::Device, "inverses");
  vk::Array<std::uint32_t> failure(context, 1, vk::MemoryClass::Host, "failure");
  const std::uint32_t none = ~0u;
  failure.upload({&none, 1});
  vk::Sequence s(context);
  s.begin();
  algebra.invertDiagonalBlocks(s, deviceA, b, inverses, failure);
  s.end();
  s.run();
  std::vector<double> values(inverses.count());
  inverses.download(values);
  std::uint32_t failed = 0;
  failure.download({&failed, 1});
  return {values, failed};
}

TEST_F(VulkanLinearAlgebra, DiagonalBlockInversesMatchEigenForEveryBlockSize) {
  const Index n = 1200;
  const compute::SparseMatrix R = randomSparse(n, n, 5, 21);
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  const compute::SparseMatrix A = compute::SparseMatrix(R.transpose() * R) + 0.1 * I;  // SPD, coupled blocks
  const Eigen::MatrixXd denseA(A);  // once: a dense copy per block is slow in the sanitizer build
  for (std::uint32_t b = 1; b <= 4; ++b) {
    SCOPED_TRACE(b);
    const auto [inverses, failed] = invertBlocksOnDevice(context(), algebra(), A, b);
    EXPECT_EQ(failed, ~0u);
    double worst = 0.0;
    for (Index first = 0; first < n; first += b) {
      const Eigen::MatrixXd block = denseA.block(first, first, b, b);
      const Eigen::MatrixXd expected = block.llt().solve(Eigen::MatrixXd::Identity(b, b));
      Eigen::MatrixXd actual(b, b);
      for (std::uint32_t i = 0; i < b; ++i) {
        for (std::uint32_t j = 0; j < b; ++j) actual(i, j) = inverses[first * b + i * b + j];
      }
      worst = std::max(worst, (actual - expected).norm() / expected.norm());
    }
    EXPECT_LT(worst, 1e-12);
  }
}

TEST_F(VulkanLinearAlgebra, DiagonalBlocksThatAreNotPositiveDefiniteAreReportedByTheFirstIndex) {
  const Index n = 400;
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  compute::SparseMatrix A = compute::SparseMatrix(randomSparse(n, n, 3, 5).transpose() * randomSparse(n, n, 3, 5)) + I;
  A.coeffRef(4 * 30 + 2, 4 * 30 + 2) = -1.0;                         // block 30 (of 4 rows) indefinite
  A.coeffRef(4 * 12 + 1, 4 * 12 + 1) = std::numeric_limits<double>::quiet_NaN();  // block 12 not finite
  const auto [inverses, failed] = invertBlocksOnDevice(context(), algebra(), A, 4);
  EXPECT_EQ(failed, 12u);
  EXPECT_EQ(inverses[4 * 30 * 4 + 5], 0.0) << "a failed block is zeros, not garbage";
  EXPECT_TRUE(std::isfinite(inverses[0]));
}

TEST_F(VulkanLinearAlgebra, AxpbyScaleRowsAndCopyMatchEigen) {
  const Eigen::MatrixXd X = randomBlock(5000, 2, 5), Y = randomBlock(5000, 2, 6);
  const Eigen::VectorXd d = randomBlock(5000, 1, 7).col(0);
  vk::DeviceVectors x = vectors(X), y = vectors(Y), z(context(), 5000, 2, "z"), w(context(), 5000, 2, "w");
  vk::Array<double> diagonal(context(), 5000, vk::MemoryClass::Device, "d");
  diagonal.upload({d.data(), 5000});
  vk::Sequence s(context());
  s.begin();
  algebra().axpby(s, 2.5, x, -0.5, y);
  algebra().scaleRows(s, diagonal, y, z);
  algebra().copy(s, z, w);
  s.end();
  s.run();
  Eigen::MatrixXd Yd, Zd, Wd;
  y.download(Yd);
  z.download(Zd);
  w.download(Wd);
  const Eigen::MatrixXd expectedY = 2.5 * X - 0.5 * Y;
  EXPECT_LT(relativeError(Yd, expectedY), 1e-12);
  EXPECT_LT(relativeError(Zd, d.asDiagonal() * expectedY), 1e-12);
  EXPECT_EQ(Wd, Zd);
}

TEST_F(VulkanLinearAlgebra, GatherSumAddsEachSourceIntoItsTargetLikeTheHost) {
  // 20 000 sources into 3 000 destinations (some unused, some sources feeding nothing):
  // the shape of a multigrid coarsening of matrix values.
  const std::size_t sources = 20000;
  const std::uint32_t count = 3000;
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::int32_t> pick(-1, static_cast<std::int32_t>(count) - 1);
  std::vector<std::int32_t> targets(sources);
  for (std::int32_t& target : targets) target = pick(rng) % 2900;  // destinations 2900 .. 2999 stay empty
  const Eigen::VectorXd values = randomBlock(static_cast<Index>(sources), 1, 12).col(0);
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(count);
  for (std::size_t i = 0; i < sources; ++i) {
    if (targets[i] >= 0) expected[targets[i]] += values[static_cast<Eigen::Index>(i)];
  }
  const vk::DeviceGather gather(context(), targets, count, "test gather");
  vk::Array<double> source(context(), sources, vk::MemoryClass::Device, "source");
  source.upload({values.data(), sources});
  vk::Array<double> destination(context(), count, vk::MemoryClass::Device, "destination");
  vk::Sequence s(context());
  s.begin();
  algebra().gatherSum(s, gather, source, destination);
  s.end();
  s.run();
  Eigen::VectorXd actual(count);
  destination.download({actual.data(), count});
  EXPECT_LT(relativeError(actual, expected), 1e-14);
  EXPECT_EQ(actual.tail(100), Eigen::VectorXd::Zero(100));

  const std::vector<std::int32_t> outside{0, 5, static_cast<std::int32_t>(count)};
  EXPECT_THROW(vk::DeviceGather(context(), outside, count, "bad gather"), Error);
  vk::Array<double> tooShort(context(), count - 1, vk::MemoryClass::Device, "short");
  EXPECT_THROW(algebra().gatherSum(s, gather, source, tooShort), Error);
}

TEST_F(VulkanLinearAlgebra, ClampProjectsOntoTheBox) {
  const Eigen::MatrixXd X = 2.0 * randomBlock(4000, 3, 8);
  const Eigen::MatrixXd L = Eigen::MatrixXd::Constant(4000, 3, -1.0) + 0.1 * randomBlock(4000, 3, 9);
  const Eigen::MatrixXd U = Eigen::MatrixXd::Constant(4000, 3, 1.0) + 0.1 * randomBlock(4000, 3, 10);
  vk::DeviceVectors x = vectors(X), l = vectors(L), u = vectors(U), y(context(), 4000, 3, "y");
  vk::Sequence s(context());
  s.begin();
  algebra().clamp(s, x, l, u, y);
  s.end();
  s.run();
  Eigen::MatrixXd Y;
  y.download(Y);
  EXPECT_EQ(Y, X.cwiseMax(L).cwiseMin(U));
  EXPECT_GT((Y - X).cwiseAbs().maxCoeff(), 0.5);  // the box was active somewhere
}

TEST_F(VulkanLinearAlgebra, MismatchedShapesAreUsageErrors) {
  vk::DeviceVectors a(context(), 10, 3, "a"), b(context(), 11, 3, "b");
  vk::Sequence s(context());
  s.begin();
  EXPECT_THROW(algebra().axpby(s, 1.0, a, 1.0, b), Error);
  s.end();
}

}  // namespace
}  // namespace plano::test
