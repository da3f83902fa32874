// Vulkan batched closest rotations against the CPU reference (Eigen JacobiSVD), 1e-10.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"

namespace plano::test {
namespace {

struct RotationComparison {
  double rotations = 0.0;
  double singularValues = 0.0;  ///< Relative to the largest singular value of the matrix.
  double orthogonality = 0.0;   ///< Largest |R^T R - I| of the device results.
  double determinant = 0.0;     ///< Largest |det R - 1|.
};

RotationComparison compare(compute::Backend& backend, const std::vector<Eigen::Matrix3d>& matrices) {
  const std::size_t n = matrices.size();
  std::vector<Eigen::Matrix3d> gpuR(n), cpuR(n);
  std::vector<Eigen::Vector3d> gpuS(n), cpuS(n);
  backend.closestRotations(matrices, gpuR, gpuS);
  compute::CpuBackend().closestRotations(matrices, cpuR, cpuS);
  RotationComparison c;
  for (std::size_t i = 0; i < n; ++i) {
    c.rotations = std::max(c.rotations, (gpuR[i] - cpuR[i]).cwiseAbs().maxCoeff());
    c.singularValues =
        std::max(c.singularValues, (gpuS[i] - cpuS[i]).cwiseAbs().maxCoeff() / std::max(cpuS[i][0], 1e-300));
    c.orthogonality = std::max(c.orthogonality,
                               (gpuR[i].transpose() * gpuR[i] - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
    c.determinant = std::max(c.determinant, std::abs(gpuR[i].determinant() - 1.0));
  }
  return c;
}

void expectAgreement(const RotationComparison& c) {
  EXPECT_LT(c.rotations, 1e-10);
  EXPECT_LT(c.singularValues, 1e-10);
  EXPECT_LT(c.orthogonality, 1e-12);
  EXPECT_LT(c.determinant, 1e-12);
}

class VulkanClosestRotations : public VulkanTest {};

TEST_F(VulkanClosestRotations, MatchesCpuOnRandomMatrices) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix3d> matrices(5000);
  for (auto& m : matrices) m = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return g(rng); });
  expectAgreement(compare(backend(), matrices));
}

TEST_F(VulkanClosestRotations, ReflectionsGetANegativeThirdSingularValue) {
  std::vector<Eigen::Matrix3d> matrices = {Eigen::Vector3d(3.0, 2.0, -1.0).asDiagonal(),
                                           Eigen::Vector3d(1.0, -1.0, 0.5).asDiagonal()};
  std::vector<Eigen::Matrix3d> R(2);
  std::vector<Eigen::Vector3d> S(2);
  backend().closestRotations(matrices, R, S);
  EXPECT_LT((S[0] - Eigen::Vector3d(3.0, 2.0, -1.0)).norm(), 1e-14);
  EXPECT_LT((R[0] - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(R[1].determinant(), 1.0, 1e-14);
  EXPECT_LT(S[1][2], 0.0);
  expectAgreement(compare(backend(), matrices));
}

TEST_F(VulkanClosestRotations, NearRotationsAndRankDeficientMatricesStayProperRotations) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix3d> matrices;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Matrix3d noise = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return g(rng); });
    const Eigen::Matrix3d R = Eigen::AngleAxisd(g(rng), Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized()).toRotationMatrix();
    matrices.push_back(2.0 * R + 1e-3 * noise);                                   // near a scaled rotation
    const Eigen::Vector3d a(g(rng), g(rng), g(rng)), b(g(rng), g(rng), g(rng)), c(g(rng), g(rng), g(rng));
    matrices.push_back(a * b.transpose() + c * a.transpose());                   // rank 2
  }
  expectAgreement(compare(backend(), matrices));
}

TEST_F(VulkanClosestRotations, EmptyBatchIsFine) {
  std::vector<Eigen::Matrix3d> none;
  std::vector<Eigen::Vector3d> s;
  EXPECT_NO_THROW(backend().closestRotations(none, none, s));
}

}  // namespace
}  // namespace plano::test
