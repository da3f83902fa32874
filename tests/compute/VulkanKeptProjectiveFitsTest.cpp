// Projective fits kept on the device (Backend::fitProjectiveMapsOnDevice) against the CPU
// reference: their first three columns and induced reciprocal scales to 1e-10, the same
// tallies, only the tallies back; and the positions of projective maps with their corner
// weights (Backend::mapPositions) to 1e-12 of the CPU's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/LocalStep.h"
#include "projective/ProjectiveTestHelpers.h"
#include "projective/ShapeSpace.h"

namespace plano::test {
namespace {

/// Normalized targets for fits of every face: a perturbed similarity of the base mesh.
Positions perturbedTargetOf(const projective::ShapeSpace& space, unsigned seed) {
  return projective::normalizedTargetPositions(space, rotatedScaledAndPerturbed(space.baseMesh().vertices, 1.1, 0.02, seed));
}

double largestDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  EXPECT_EQ(a.rows(), b.rows());
  EXPECT_EQ(a.cols(), b.cols());
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  return a.size() == 0 ? 0.0 : (a - b).cwiseAbs().maxCoeff();
}

class VulkanKeptProjectiveFits : public VulkanTest {};

TEST_F(VulkanKeptProjectiveFits, AgreeWithTheCpuAndOnlyTheirTalliesComeBack) {
  for (const PolygonMesh& mesh : {generate::translationalSurface(7, 5), generate::hexagonalDome(2)}) {
    const projective::ShapeSpace space(mesh);
    const Positions first = perturbedTargetOf(space, 3);
    const Positions second = perturbedTargetOf(space, 4);
    compute::CpuBackend cpu;
    compute::DeviceProjectiveFits reference, kept;
    cpu.fitProjectiveMapsOnDevice(mesh.faces, space.basePositions(), second, 1e-10, reference);
    backend().fitProjectiveMapsOnDevice(mesh.faces, space.basePositions(), first, 1e-10, kept);

    // The second fit uploads its target alone; down come the two tallies.
    const vk::TransferCounts before = context().transfers();
    backend().fitProjectiveMapsOnDevice(mesh.faces, space.basePositions(), second, 1e-10, kept);
    const vk::TransferCounts after = context().transfers();
    EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(second.size()) * 8u);
    EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, 8u);
    ASSERT_FALSE(kept.linearColumns.onHost());
    ASSERT_FALSE(kept.reciprocalScales.onHost());

    EXPECT_LT(largestDifference(kept.linearColumns.values(), reference.linearColumns.values()), 1e-10);
    EXPECT_LT(largestDifference(kept.reciprocalScales.values(), reference.reciprocalScales.values()), 1e-10);
    EXPECT_EQ(kept.nonPositiveScales, reference.nonPositiveScales);
    EXPECT_EQ(kept.firstVanishingCorner, -1);
    EXPECT_EQ(reference.firstVanishingCorner, -1);
    // The reference's scales are the shape space's induced ones, and they are not all 1
    // (projective fits, not affine ones: the weights matter below).
    compute::ProjectiveFits fits;
    cpu.fitProjectiveMaps(mesh.faces, space.basePositions(), second, fits);
    const std::vector<double> induced = space.inducedReciprocalScales(fits.maps);
    const Eigen::Map<const Eigen::VectorXd> inducedColumn(induced.data(), static_cast<Eigen::Index>(induced.size()));
    EXPECT_EQ(largestDifference(reference.reciprocalScales.values(), inducedColumn), 0.0);
    EXPECT_GT((inducedColumn.array() - 1.0).abs().maxCoeff(), 1e-3);
  }
}

TEST_F(VulkanKeptProjectiveFits, TalliesNameTheFirstVanishingCornerAndCountNonPositiveScales) {
  // A projective image of the base whose vanishing plane w = 0 crosses the mesh: faces
  // across it get corners of both signs.
  const PolygonMesh mesh = generate::translationalSurface(8, 6);
  const projective::ShapeSpace space(mesh);
  Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
  H(0, 3) = 3.7;  // w = 3.7 x + 1: zero at x = -0.27, inside the normalized mesh
  const Positions base = space.basePositions();
  Positions target = applyProjectiveMap(base, H);
  compute::CpuBackend cpu;
  compute::DeviceProjectiveFits reference, kept;
  cpu.fitProjectiveMapsOnDevice(mesh.faces, base, target, 1e-10, reference);
  backend().fitProjectiveMapsOnDevice(mesh.faces, base, target, 1e-10, kept);
  EXPECT_GT(reference.nonPositiveScales, 0);
  EXPECT_EQ(kept.nonPositiveScales, reference.nonPositiveScales);

  // A limit above the smallest scales: the lowest corner below it, on both.
  Eigen::VectorXd magnitudes = reference.reciprocalScales.values().col(0).cwiseAbs();
  std::vector<double> sorted(magnitudes.data(), magnitudes.data() + magnitudes.size());
  std::sort(sorted.begin(), sorted.end());
  const double limit = sorted[sorted.size() / 2];
  cpu.fitProjectiveMapsOnDevice(mesh.faces, base, target, limit, reference);
  backend().fitProjectiveMapsOnDevice(mesh.faces, base, target, limit, kept);
  ASSERT_GE(reference.firstVanishingCorner, 0);
  EXPECT_EQ(kept.firstVanishingCorner, reference.firstVanishingCorner);
  for (Index c = 0; c < reference.firstVanishingCorner; ++c) EXPECT_GT(magnitudes[c], limit) << "corner " << c;

  // A non-finite target makes a scale NaN: counted as vanishing (and not positive).
  target(5, 0) = std::nan("");
  backend().fitProjectiveMapsOnDevice(mesh.faces, base, target, 1e-10, kept);
  EXPECT_GE(kept.firstVanishingCorner, 0);
}

TEST_F(VulkanKeptProjectiveFits, PositionsOfCompatibleProjectiveFitsAreTheTargetOnBothBackends) {
  // Every face fitted to one projective image of the mesh: the fits agree at shared
  // corners, so the dehomogenized corner images are the image itself.
  for (const PolygonMesh& mesh : {generate::translationalSurface(6, 4), generate::hexagonalDome(2)}) {
    const projective::ShapeSpace space(mesh);
    const Positions base = space.basePositions();
    const Positions target = applyProjectiveMap(base, samplePerspective());
    const compute::VertexCorners corners = space.vertexCorners();
    compute::CpuBackend cpu;
    compute::DeviceProjectiveFits reference, kept;
    cpu.fitProjectiveMapsOnDevice(mesh.faces, base, target, 1e-10, reference);
    backend().fitProjectiveMapsOnDevice(mesh.faces, base, target, 1e-10, kept);
    const Eigen::MatrixXd columns = reference.linearColumns.values();  // as an ADMM's solution would be

    // Affine positions of the same columns (weights 1) are not the target: the weights
    // count. (This run also uploads the topology and the base, which the next one keeps.)
    compute::MapPositions unweighted;
    backend().mapPositions(mesh.faces, base, corners, columns, {}, Eigen::MatrixXd(base), unweighted);
    EXPECT_GT(largestDifference(unweighted.positions.values(), target), 1e-3);

    compute::MapPositions onCpu, onDevice;
    cpu.mapPositions(mesh.faces, base, corners, columns, reference.reciprocalScales, Eigen::MatrixXd(base), onCpu);
    const vk::TransferCounts before = context().transfers();
    backend().mapPositions(mesh.faces, base, corners, columns, kept.reciprocalScales, Eigen::MatrixXd(base), onDevice);
    const vk::TransferCounts after = context().transfers();
    // Up the columns and the previous positions; the weights are bound where they are.
    EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(columns.size() + base.size()) * 8u);
    EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, 16u);

    EXPECT_LT(largestDifference(onCpu.positions.values(), target), 1e-10);
    EXPECT_LT(largestDifference(onDevice.positions.values(), onCpu.positions.values()), 1e-12);
    EXPECT_NEAR(onDevice.displacement, onCpu.displacement, 1e-12);
    EXPECT_GT(onCpu.displacement, 1e-2);  // the image is far from the base
    EXPECT_NEAR(onDevice.maxPlanarity, onCpu.maxPlanarity, 1e-9);
  }
}

TEST_F(VulkanKeptProjectiveFits, CornerWeightsOfTheWrongSizeAreUsageErrorsOnBothBackends) {
  const PolygonMesh mesh = generate::translationalSurface(3, 3);
  const projective::ShapeSpace space(mesh);
  const Positions base = space.basePositions();
  const Eigen::MatrixXd columns = Eigen::MatrixXd::Random(4 * space.faceCount(), 3);
  compute::CpuBackend cpu;
  for (compute::Backend* on : {static_cast<compute::Backend*>(&backend()), static_cast<compute::Backend*>(&cpu)}) {
    compute::MapPositions out;
    try {
      on->mapPositions(mesh.faces, base, space.vertexCorners(), columns, Eigen::MatrixXd::Ones(5, 1),
                       Eigen::MatrixXd(base), out);
      ADD_FAILURE() << on->name() << ": expected Error(Usage)";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
    }
  }
}

}  // namespace
}  // namespace plano::test
