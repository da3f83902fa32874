// Vulkan per-face planarity against the CPU reference (fp64, 1e-12 relative).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "compute/KernelComparisons.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanFacePlanarity.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

/// Random polygon soup: faces of 3..7 distinct random vertices of random positions.
PolygonMesh randomPolygons(Index vertexCount, Index faceCount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::uniform_int_distribution<Index> degree(3, 7);
  PolygonMesh mesh;
  mesh.vertices.resize(vertexCount, 3);
  for (Index i = 0; i < mesh.vertices.size(); ++i) mesh.vertices.data()[i] = coordinate(rng);
  std::vector<Index> all(vertexCount);
  for (Index v = 0; v < vertexCount; ++v) all[v] = v;
  for (Index f = 0; f < faceCount; ++f) {
    std::shuffle(all.begin(), all.end(), rng);
    mesh.faces.addFace(std::span<const Index>(all.data(), static_cast<std::size_t>(degree(rng))));
  }
  return mesh;
}

class VulkanFacePlanarity : public VulkanTest {};

TEST_F(VulkanFacePlanarity, MatchesCpuOnRandomPolygons) {
  EXPECT_LT(planarityDifference(backend(), randomPolygons(200, 3000, 1)), 1e-12);
}

TEST_F(VulkanFacePlanarity, MatchesCpuOnGeneratedQuadMeshes) {
  EXPECT_LT(planarityDifference(backend(), generate::translationalSurface(40, 30)), 1e-12);
  EXPECT_LT(planarityDifference(backend(), generate::surfaceOfRevolution(32, 12)), 1e-12);
  EXPECT_LT(planarityDifference(backend(), generate::hyparGrid(50, 0.7)), 1e-12);
  EXPECT_LT(planarityDifference(backend(), generate::cube()), 1e-12);
}

TEST_F(VulkanFacePlanarity, MatchesCpuOnPentagonsAndHexagons) {
  EXPECT_LT(planarityDifference(backend(), generate::dodecahedron()), 1e-12);
  EXPECT_LT(planarityDifference(backend(), generate::hexagonalDome(12)), 1e-12);
  PolygonMesh noisy = generate::hexagonalDome(10);
  noisy.vertices = perturbed(noisy.vertices, 0.01);
  EXPECT_LT(planarityDifference(backend(), noisy), 1e-12);
}

TEST_F(VulkanFacePlanarity, NonPlanarFacesHaveTheCpuValuesNotJustZero) {
  // Guards against a kernel that writes zeros: the hypar grid's faces are clearly skew.
  const PolygonMesh mesh = generate::hyparGrid(8, 0.5);
  std::vector<double> values(mesh.faceCount());
  backend().facePlanarity(mesh, values);
  EXPECT_GT(*std::max_element(values.begin(), values.end()), 0.1);
}

TEST_F(VulkanFacePlanarity, EmptyMeshGivesNoValues) {
  PolygonMesh mesh;
  std::vector<double> values;
  EXPECT_NO_THROW(backend().facePlanarity(mesh, values));
}

TEST_F(VulkanFacePlanarity, StagingUploadPathGivesTheSameValues) {
  // The discrete-GPU path (device-local memory + staging copies), forced on lavapipe.
  vk::ContextSettings settings = vk::ContextSettings::fromEnvironment(vk::DeviceSelection::Any);
  settings.validation = true;
  settings.forceStaging = true;
  vk::Context staged(settings);
  vk::FacePlanarityKernel kernel(staged);
  PolygonMesh mesh = generate::hyparGrid(30, 0.4);
  std::vector<double> gpu(mesh.faceCount()), cpu(mesh.faceCount());
  kernel.run(mesh, gpu);
  compute::CpuBackend().facePlanarity(mesh, cpu);
  for (Index f = 0; f < mesh.faceCount(); ++f) ASSERT_NEAR(gpu[f], cpu[f], 1e-12 * std::max(cpu[f], 1.0)) << "face " << f;
  EXPECT_EQ(staged.validationMessageCount(), 0u) << (staged.validationMessages().empty() ? "" : staged.validationMessages()[0]);
}

}  // namespace
}  // namespace plano::test

namespace plano::test {
namespace {

class VulkanFaceChecks : public VulkanTest {};

TEST_F(VulkanFaceChecks, OutOfRangeCornerIsBadInputNamingTheFace) {
  PolygonMesh mesh = generate::cube();
  mesh.faces.addFace({0, 1, 8, 3});  // vertex 8 does not exist
  std::vector<double> values(mesh.faceCount());
  try {
    backend().facePlanarity(mesh, values);
    FAIL() << "expected Error(BadInput)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("face 6"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vertex 8"), std::string::npos) << e.what();
  }
  compute::ProjectiveFits fits;
  EXPECT_THROW(backend().fitProjectiveMaps(mesh.faces, mesh.vertices, mesh.vertices, fits), Error);
}

TEST_F(VulkanFaceChecks, RepeatedCallsOnMeshesOfDifferentSizesReuseBuffersCorrectly) {
  // Kernels keep their buffers between calls (grow-only): shrinking and growing again
  // must neither read stale data nor overrun.
  for (Index n : {30, 4, 17, 45}) {
    PolygonMesh mesh = generate::hyparGrid(n, 0.3);
    EXPECT_LT(planarityDifference(backend(), mesh), 1e-12) << "n " << n;
    compute::ProjectiveFits gpu, cpu;
    const Positions target = perturbed(mesh.vertices, 0.01, static_cast<unsigned>(n));
    backend().fitProjectiveMaps(mesh.faces, mesh.vertices, target, gpu);
    compute::CpuBackend().fitProjectiveMaps(mesh.faces, mesh.vertices, target, cpu);
    ASSERT_EQ(gpu.maps.size(), cpu.maps.size());
    for (Index f = 0; f < mesh.faceCount(); ++f) {
      // Relative to the entries, as in VulkanProjectiveFitTest: on the finest grid the 0.01
      // perturbation is about half a face, and the maps (converted back from face-centred
      // coordinates) have entries far above 1.
      const double scale = std::max(1.0, cpu.maps[f].cwiseAbs().maxCoeff());
      ASSERT_LT((gpu.maps[f] - cpu.maps[f]).cwiseAbs().maxCoeff() / scale, 1e-10)
          << "n " << n << " face " << f << " largest entry " << scale;
    }
  }
}

TEST_F(VulkanFaceChecks, SequenceReportsDeviceTimeFromTimestamps) {
  if (context().info().timestampPeriodNs <= 0.0) GTEST_SKIP() << "queue without timestamps";
  vk::Sequence sequence(context());
  EXPECT_LT(sequence.lastDeviceSeconds(), 0.0);  // nothing ran yet
  vk::Array<double> a(context(), 1024, vk::MemoryClass::Device, "a"), b(context(), 1024, vk::MemoryClass::Device, "b");
  sequence.begin();
  sequence.copy(a, b, 1024 * sizeof(double));
  sequence.end();
  sequence.run();
  sequence.run();  // a recorded sequence replays
  EXPECT_GE(sequence.lastDeviceSeconds(), 0.0);
  EXPECT_LT(sequence.lastDeviceSeconds(), 10.0);
}

}  // namespace
}  // namespace plano::test
