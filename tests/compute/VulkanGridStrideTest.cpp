// Every kernel loops grid-stride because a dispatch dimension holds at most 65535
// workgroups (fewer items than a 1M-face mesh has at 8 or 64 per group). With the
// workgroup cap lowered to 3, small inputs take the same many-items-per-invocation path.
#include <gtest/gtest.h>

#include <random>

#include "compute/MeshMatrices.h"
#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanClosestRotations.h"
#include "compute/vulkan/VulkanContext.h"
#include "compute/vulkan/VulkanFacePlanarity.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "compute/vulkan/VulkanPcgSolver.h"
#include "compute/vulkan/VulkanProjectiveFit.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanGridStride : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    vk::ContextSettings settings = vk::ContextSettings::fromEnvironment(vk::DeviceSelection::Any);
    settings.validation = true;
    settings.maxWorkGroups = 3;
    try {
      context_ = std::make_unique<vk::Context>(settings);
    } catch (const Error& e) {
      error_ = e.what();
    }
  }
  static void TearDownTestSuite() { context_.reset(); }
  void SetUp() override { ASSERT_TRUE(context_) << error_; }
  void TearDown() override {
    const auto messages = context_->validationMessages();
    EXPECT_TRUE(messages.empty()) << messages.front();
  }
  vk::Context& context() { return *context_; }

  static inline std::unique_ptr<vk::Context> context_;
  static inline std::string error_;
};

TEST_F(VulkanGridStride, PlanarityCoversEveryFace) {
  ASSERT_EQ(context().info().maxWorkGroupCount[0], 3u);
  PolygonMesh mesh = generate::hyparGrid(30, 0.6);  // 900 faces > 3 x 64 invocations
  std::vector<double> gpu(mesh.faceCount()), cpu(mesh.faceCount());
  vk::FacePlanarityKernel(context()).run(mesh, gpu);
  compute::CpuBackend().facePlanarity(mesh, cpu);
  for (Index f = 0; f < mesh.faceCount(); ++f) ASSERT_NEAR(gpu[f], cpu[f], 1e-12 * std::max(1.0, cpu[f])) << f;
}

TEST_F(VulkanGridStride, ProjectiveFitsCoverEveryFace) {
  const PolygonMesh mesh = generate::translationalSurface(8, 8);  // 64 faces > 3 x 8 invocations
  const Positions target = perturbed(mesh.vertices, 0.01, 4);
  compute::ProjectiveFits gpu, cpu;
  vk::ProjectiveFitKernel(context()).run(mesh.faces, mesh.vertices, target, gpu);
  compute::CpuBackend().fitProjectiveMaps(mesh.faces, mesh.vertices, target, cpu);
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    ASSERT_LT((gpu.maps[f] - cpu.maps[f]).cwiseAbs().maxCoeff(), 1e-10) << "face " << f;
    ASSERT_EQ(gpu.ranks[f], cpu.ranks[f]) << "face " << f;
  }
}

TEST_F(VulkanGridStride, RotationsCoverEveryMatrix) {
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  std::vector<Eigen::Matrix3d> matrices(500);
  for (auto& m : matrices) m = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return g(rng); });
  std::vector<Eigen::Matrix3d> gpuR(500), cpuR(500);
  std::vector<Eigen::Vector3d> gpuS(500), cpuS(500);
  vk::ClosestRotationsKernel(context()).run(matrices, gpuR, gpuS);
  compute::CpuBackend().closestRotations(matrices, cpuR, cpuS);
  for (std::size_t i = 0; i < matrices.size(); ++i) ASSERT_LT((gpuR[i] - cpuR[i]).norm(), 1e-10) << i;
}

TEST_F(VulkanGridStride, PcgSolveConverges) {
  const PolygonMesh mesh = generate::translationalSurface(20, 20);  // 441 rows > 3 x 64
  const compute::SparseMatrix A = laplacianLikeSpd(mesh, 0.1);
  const Eigen::MatrixXd B = mesh.vertices;
  compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-10;
  vk::PcgSolver solver(context(), A, settings);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(B.rows(), 3);
  const compute::LinearSolveInfo info = solver.solve(B, X);
  EXPECT_TRUE(info.converged);
  EXPECT_LE((A * X - B).norm() / B.norm(), 1.5e-10);
}

}  // namespace
}  // namespace plano::test
