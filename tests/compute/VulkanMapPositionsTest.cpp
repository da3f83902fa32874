// Vulkan positions from affine face maps (Backend::mapPositions) against the CPU
// reference, with the displacement and planarity measured on the device: positions to
// 1e-12, the same measures, only two scalars back, and the positions bound where they are.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/IdealMaps.h"
#include "projective/ProjectiveTestHelpers.h"
#include "projective/ShapeSpace.h"

namespace plano::test {
namespace {

/// Incompatible affine maps: the ideal maps of a perturbed motion, each entry perturbed
/// again (so a vertex's corner images differ and their mean is what is tested).
Eigen::MatrixXd perturbedIdealColumns(const projective::ShapeSpace& space, unsigned seed) {
  compute::CpuBackend cpu;
  const Positions target = rotatedScaledAndPerturbed(space.baseMesh().vertices, 1.1, 0.02, seed);
  Eigen::MatrixXd columns =
      projective::fittedIdealMapsOnDevice(cpu, space, target, projective::IdealMapKind::Similar).values();
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1e-3);
  for (Eigen::Index i = 0; i < columns.size(); ++i) columns.data()[i] += normal(rng);
  return columns;
}

class VulkanMapPositions : public VulkanTest {};

TEST_F(VulkanMapPositions, AgreeWithTheCpuAndOnlyTheirMeasuresComeBack) {
  for (const PolygonMesh& mesh : {generate::translationalSurface(7, 5), generate::hexagonalDome(2)}) {
    const projective::ShapeSpace space(mesh);
    const compute::VertexCorners corners = space.vertexCorners();
    const Eigen::MatrixXd first = perturbedIdealColumns(space, 3);
    const Eigen::MatrixXd second = perturbedIdealColumns(space, 4);
    const Eigen::MatrixXd start = Eigen::MatrixXd(space.basePositions());

    compute::CpuBackend cpu;
    compute::MapPositions cpuFirst, cpuSecond, gpuFirst, gpuSecond;
    cpu.mapPositions(mesh.faces, space.basePositions(), corners, first, {}, start, cpuFirst);
    cpu.mapPositions(mesh.faces, space.basePositions(), corners, second, {}, cpuFirst.positions, cpuSecond);
    backend().mapPositions(mesh.faces, space.basePositions(), corners, first, {}, start, gpuFirst);
    EXPECT_FALSE(gpuFirst.positions.onHost());

    // The second step reads the first's positions where they are: up only the columns,
    // down the two measures.
    const vk::TransferCounts before = context().transfers();
    backend().mapPositions(mesh.faces, space.basePositions(), corners, second, {}, gpuFirst.positions, gpuSecond);
    const vk::TransferCounts after = context().transfers();
    EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(second.size()) * 8u);
    EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, 16u);

    for (const auto& [gpu, host] : {std::pair{&gpuFirst, &cpuFirst}, std::pair{&gpuSecond, &cpuSecond}}) {
      EXPECT_LT((gpu->positions.values() - host->positions.values()).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_NEAR(gpu->displacement, host->displacement, 1e-12);
      EXPECT_NEAR(gpu->maxPlanarity, host->maxPlanarity, 1e-9 * std::max(1.0, host->maxPlanarity));
      EXPECT_GT(host->displacement, 1e-3);  // the maps moved the mesh: the comparison means something
      EXPECT_GT(host->maxPlanarity, 1e-3);  // perturbed maps bend the faces
    }
    // Both results stay readable: the second step wrote the other array.
    EXPECT_LT((gpuFirst.positions.values() - cpuFirst.positions.values()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST_F(VulkanMapPositions, PositionsFromANewerStepReplaceTheOldestOnly) {
  const PolygonMesh mesh = generate::translationalSurface(4, 4);
  const projective::ShapeSpace space(mesh);
  const compute::VertexCorners corners = space.vertexCorners();
  const Eigen::MatrixXd start = Eigen::MatrixXd(space.basePositions());
  compute::MapPositions a, b, c;
  backend().mapPositions(mesh.faces, space.basePositions(), corners, perturbedIdealColumns(space, 1), {}, start, a);
  backend().mapPositions(mesh.faces, space.basePositions(), corners, perturbedIdealColumns(space, 2), {}, a.positions, b);
  backend().mapPositions(mesh.faces, space.basePositions(), corners, perturbedIdealColumns(space, 3), {}, b.positions, c);
  try {
    (void)a.positions.values();  // its array now holds c's
    ADD_FAILURE() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
  }
  EXPECT_EQ(b.positions.values().rows(), mesh.vertices.rows());
  EXPECT_EQ(c.positions.values().rows(), mesh.vertices.rows());
}

TEST_F(VulkanMapPositions, NonFiniteMapsAreNumericalErrorsAndWrongSizesUsageErrorsOnBothBackends) {
  const PolygonMesh mesh = generate::translationalSurface(3, 3);
  const projective::ShapeSpace space(mesh);
  const compute::VertexCorners corners = space.vertexCorners();
  const Eigen::MatrixXd start = Eigen::MatrixXd(space.basePositions());
  Eigen::MatrixXd columns = perturbedIdealColumns(space, 5);
  columns(5, 1) = std::nan("");
  compute::CpuBackend cpu;
  for (compute::Backend* on : {static_cast<compute::Backend*>(&backend()), static_cast<compute::Backend*>(&cpu)}) {
    compute::MapPositions out;
    try {
      on->mapPositions(mesh.faces, space.basePositions(), corners, columns, {}, start, out);
      ADD_FAILURE() << on->name() << ": expected Error(Numerical)";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Numerical) << e.what();
    }
    try {
      on->mapPositions(mesh.faces, space.basePositions(), corners, columns.topRows(8), {}, start, out);
      ADD_FAILURE() << on->name() << ": expected Error(Usage)";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
    }
  }
}

}  // namespace
}  // namespace plano::test
