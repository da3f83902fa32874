// The reduced operator N^T (S (x) I_k) N on Vulkan against the CPU reference (fp64, 1e-12
// relative), on random operators and bases and on the linear spaces of generated meshes.
#include <gtest/gtest.h>

#include <random>

#include "compute/ReducedOperator.h"
#include "compute/VulkanFixture.h"
#include "compute/vulkan/VulkanReducedOperator.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "subspace/Eigenshapes.h"
#include "subspace/FundamentalShapes.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

/// A random #V x #V sparse matrix (about `perRow` entries per row, not symmetric).
compute::SparseMatrix randomOperator(Index vertices, int perRow, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> column(0, vertices - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (Index v = 0; v < vertices; ++v)
    for (int e = 0; e < perRow; ++e) entries.emplace_back(v, column(rng), value(rng));
  compute::SparseMatrix S(vertices, vertices);
  S.setFromTriplets(entries.begin(), entries.end());
  return S;
}

using VulkanReducedOperator = VulkanTest;

TEST_F(VulkanReducedOperator, MatchesTheCpuOnRandomOperatorsAndBases) {
  // Sizes off the kernel's 64-column tiles and 16-row slices (150 columns: three tiles per
  // side), one and three coordinates per vertex.
  const compute::SparseMatrix S = randomOperator(301, 7, 1);
  for (const auto& [k, columns] : {std::pair{1, 37}, std::pair{3, 29}, std::pair{1, 150}}) {
    const Eigen::MatrixXd N = gaussianMatrix(k * 301, columns, 2 + k + columns);
    const Eigen::MatrixXd R = backend().reducedOperator(S, N, k);
    ASSERT_EQ(R.rows(), N.cols());
    ASSERT_EQ(R.cols(), N.cols());
    EXPECT_LT(relativeMaxDifference(R, compute::reducedOperatorReference(S, N, k)), 1e-12)
        << k << " coordinates, " << columns << " columns";
  }
}

TEST_F(VulkanReducedOperator, ABasisSplitIntoManyBlocksGivesTheSameOperator) {
  const compute::SparseMatrix S = randomOperator(200, 5, 4);
  const Eigen::MatrixXd N = gaussianMatrix(3 * 200, 41, 5);
  // Five columns per block: nine blocks of columns, 81 products of blocks.
  vk::ReducedOperatorKernel kernel(context(), 5 * static_cast<std::size_t>(N.rows()) * sizeof(double));
  const Eigen::MatrixXd blocked = kernel.run(S, N, 3);
  EXPECT_LT(relativeMaxDifference(blocked, compute::reducedOperatorReference(S, N, 3)), 1e-12);
  EXPECT_LT(relativeMaxDifference(blocked, backend().reducedOperator(S, N, 3)), 1e-13);
}

TEST_F(VulkanReducedOperator, ATallBasisSplitIntoChunksOfRowsGivesTheSameOperator) {
  // 4 500 rows: three chunks of the long dimension (the last one short), summed at the end.
  const compute::SparseMatrix S = randomOperator(1500, 6, 10);
  const Eigen::MatrixXd N = gaussianMatrix(3 * 1500, 70, 11);
  EXPECT_LT(relativeMaxDifference(backend().reducedOperator(S, N, 3), compute::reducedOperatorReference(S, N, 3)), 1e-12);
}

TEST_F(VulkanReducedOperator, OnlyTheSmallResultComesBack) {
  const compute::SparseMatrix S = randomOperator(500, 6, 6);
  const Eigen::MatrixXd N = gaussianMatrix(500, 24, 7);
  (void)backend().reducedOperator(S, N, 1);  // pipelines built
  const auto before = backend().transfers();
  (void)backend().reducedOperator(S, N, 1);
  const auto moved = compute::transfersSince(before, backend().transfers());
  ASSERT_TRUE(moved.has_value());
  EXPECT_EQ(moved->downloadedBytes, static_cast<std::uint64_t>(24 * 24 * sizeof(double)));
  EXPECT_GE(moved->uploadedBytes, static_cast<std::uint64_t>(N.size() * sizeof(double)));
}

TEST_F(VulkanReducedOperator, AnEmptyBasisGivesAnEmptyOperator) {
  const compute::SparseMatrix S = randomOperator(10, 2, 8);
  EXPECT_EQ(backend().reducedOperator(S, Eigen::MatrixXd(30, 0), 3).size(), 0);
}

TEST_F(VulkanReducedOperator, MismatchedSizesAreUsageErrors) {
  const compute::SparseMatrix S = randomOperator(10, 2, 9);
  try {
    (void)backend().reducedOperator(S, Eigen::MatrixXd::Ones(20, 4), 3);
    FAIL() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_NE(std::string(e.what()).find("20 rows for 10 vertices of 3 coordinates"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)backend().reducedOperator(S, Eigen::MatrixXd::Ones(10, 4), 0), Error);
}

TEST_F(VulkanReducedOperator, EigenshapesAndFundamentalShapesMatchTheCpuOnGeneratedSpaces) {
  const PolygonMesh mesh = generate::translationalSurface(9, 7);
  const compute::SparseMatrix L = subspace::uniformLaplacian(mesh.faces, mesh.vertexCount());
  for (subspace::SpaceKind kind : {subspace::SpaceKind::Affine, subspace::SpaceKind::Parallel}) {
    const subspace::LinearSpace space =
        subspace::buildLinearSpace(mesh, subspace::uniformAssignment(kind, mesh.faceCount()));
    EXPECT_LT(relativeMaxDifference(space.N.reducedOperator(backend(), L), space.N.reducedOperator(L)), 1e-12)
        << subspace::toString(kind);
    subspace::EigenshapeSettings settings;
    settings.count = 12;
    const subspace::Eigenshapes device = subspace::computeEigenshapes(backend(), space.N, L, settings);
    const subspace::Eigenshapes host = subspace::computeEigenshapes(space.N, L, settings);
    ASSERT_EQ(device.count(), host.count());
    EXPECT_LT((device.frequencies - host.frequencies).cwiseAbs().maxCoeff(), 1e-10 * host.frequencies.maxCoeff())
        << subspace::toString(kind);
    const Positions shape = subspace::fundamentalShape(backend(), space.N, L, 10, Eigen::Vector3d(0.0, 0.0, 1.0));
    const Positions reference = subspace::fundamentalShape(space.N, L, 10, Eigen::Vector3d(0.0, 0.0, 1.0));
    EXPECT_LT((shape - reference).cwiseAbs().maxCoeff(), 1e-10 * reference.cwiseAbs().maxCoeff())
        << subspace::toString(kind);
  }
}

}  // namespace
}  // namespace plano::test
