// The CPU reduced operator's symmetric product (compute/cpu/SymmetricProduct.h) against
// Eigen's full product, and the reduced operator's choice between the two.
#include <gtest/gtest.h>

#include <random>

#include "compute/ReducedOperator.h"
#include "compute/cpu/SymmetricProduct.h"
#include "core/Cancellation.h"
#include "core/Error.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

/// A path-graph Laplacian on `vertices` vertices plus `extra` random symmetric couplings.
compute::SparseMatrix pathLaplacianWithCouplings(Index vertices, unsigned seed, bool symmetric = true) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> vertex(0, vertices - 1);
  std::vector<Eigen::Triplet<double>> entries;
  for (Index v = 0; v + 1 < vertices; ++v) {
    entries.emplace_back(v, v, 1.0);
    entries.emplace_back(v + 1, v + 1, 1.0);
    entries.emplace_back(v, v + 1, -1.0);
    entries.emplace_back(v + 1, v, symmetric ? -1.0 : -0.5);
  }
  for (Index e = 0; e < vertices; ++e) {
    const Index a = vertex(rng), b = vertex(rng);
    entries.emplace_back(a, b, 0.25);
    entries.emplace_back(b, a, 0.25);
  }
  compute::SparseMatrix S(vertices, vertices);
  S.setFromTriplets(entries.begin(), entries.end());
  return S;
}

TEST(SymmetricProduct, LowerBlocksMirroredEqualTheFullProductOfASymmetricOne) {
  // 600 columns: five blocks of columns, the last one short.
  const compute::SparseMatrix S = pathLaplacianWithCouplings(700, 1);
  const Eigen::MatrixXd N = gaussianMatrix(700, 600, 2);
  const Eigen::MatrixXd SN = S * N;
  const Eigen::MatrixXd R = compute::symmetricTransposeProduct(N, SN);
  const Eigen::MatrixXd full = N.transpose() * SN;
  EXPECT_LT(relativeMaxDifference(R, full), 1e-13);
  EXPECT_EQ(R, R.transpose());
}

TEST(SymmetricProduct, TheReducedOperatorOfANonSymmetricOperatorIsTheFullProduct) {
  const compute::SparseMatrix S = pathLaplacianWithCouplings(300, 3, false);
  const Eigen::MatrixXd N = gaussianMatrix(300, 280, 4);
  const Eigen::MatrixXd R = compute::reducedOperatorReference(S, N, 1);
  EXPECT_EQ(R, Eigen::MatrixXd(N.transpose() * (S * N)));
  EXPECT_GT((R - R.transpose()).cwiseAbs().maxCoeff(), 1.0);
}

TEST(SymmetricProduct, TheReducedOperatorOfASymmetricOperatorIsSymmetricOnEveryCoordinateCount) {
  const compute::SparseMatrix S = pathLaplacianWithCouplings(200, 5);
  for (int k : {1, 3}) {
    const Eigen::MatrixXd N = gaussianMatrix(k * 200, 300, 6 + k);
    const Eigen::MatrixXd R = compute::reducedOperatorReference(S, N, k);
    EXPECT_EQ(R, R.transpose()) << k;
    // k = 3: S acts on each coordinate of a vertex alike, (S (x) I_3) N.
    Eigen::MatrixXd SN(N.rows(), N.cols());
    for (Index v = 0; v < 200; ++v)
      for (int c = 0; c < k; ++c) {
        SN.row(k * v + c).setZero();
        for (compute::SparseMatrix::InnerIterator it(S, v); it; ++it) SN.row(k * v + c) += it.value() * N.row(k * it.col() + c);
      }
    EXPECT_LT(relativeMaxDifference(R, N.transpose() * SN), 1e-13) << k;
  }
}

TEST(SymmetricProduct, ACancellationRequestStopsIt) {
  const Eigen::MatrixXd N = gaussianMatrix(50, 300, 8);
  requestCancellation();
  EXPECT_THROW(compute::symmetricTransposeProduct(N, N), Interrupted);
  clearCancellation();
  EXPECT_EQ(compute::symmetricTransposeProduct(N, N).rows(), 300);
}

TEST(SymmetricProduct, FactorsOfDifferentSizesAreAUsageError) {
  const Eigen::MatrixXd A = gaussianMatrix(10, 4, 9), B = gaussianMatrix(10, 5, 10);
  try {
    compute::symmetricTransposeProduct(A, B);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
  }
}

}  // namespace
}  // namespace plano::test
