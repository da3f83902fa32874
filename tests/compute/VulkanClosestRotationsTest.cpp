// Vulkan batched closest rotations against the CPU reference (Eigen JacobiSVD), 1e-10.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "compute/KernelComparisons.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"

namespace plano::test {
namespace {

class VulkanClosestRotations : public VulkanTest {};

TEST_F(VulkanClosestRotations, MatchesCpuOnRandomMatrices) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix3d> matrices(5000);
  for (auto& m : matrices) m = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return g(rng); });
  expectRotationAgreement(compareRotations(backend(), matrices));
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
  expectRotationAgreement(compareRotations(backend(), matrices));
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
  expectRotationAgreement(compareRotations(backend(), matrices));
}

TEST_F(VulkanClosestRotations, EmptyBatchIsFine) {
  std::vector<Eigen::Matrix3d> none;
  std::vector<Eigen::Vector3d> s;
  EXPECT_NO_THROW(backend().closestRotations(none, none, s));
}

}  // namespace
}  // namespace plano::test
