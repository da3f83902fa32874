// Vulkan batched closest ideal maps against the CPU reference (projective/IdealMapFit):
// maps to 1e-10 and the same method per face, on fits of generated meshes under
// perspective and random motions, rigid and similar, with the corner-set fallback.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "compute/KernelComparisons.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/GlobalStep.h"
#include "projective/IdealMaps.h"
#include "projective/LocalStep.h"
#include "projective/ProjectiveTestHelpers.h"

namespace plano::test {
namespace {

/// The CPU fits of `target` (world) from the base mesh, in the shape space's coordinates.
struct Fitted {
  projective::ShapeSpace space;
  std::vector<Eigen::Matrix4d> maps;
  Positions normalizedTarget;
};

Fitted fit(const PolygonMesh& mesh, const Positions& target) {
  Fitted out{projective::ShapeSpace(mesh), {}, {}};
  compute::CpuBackend cpu;
  out.maps = projective::fitFaceMaps(cpu, out.space, target).fits.maps;
  out.normalizedTarget = out.space.normalization().toNormalized(target);
  return out;
}

class VulkanIdealMaps : public VulkanTest {};

TEST_F(VulkanIdealMaps, AgreeWithTheCpuOnPerspectiveFitsOfHexagonsRigidAndSimilar) {
  const PolygonMesh mesh = generate::hexagonalDome(2);
  const projective::ShapeSpace space(mesh);
  const Positions target =
      space.normalization().toWorld(applyProjectiveMap(space.basePositions(), samplePerspective()));
  const Fitted f = fit(mesh, target);
  for (const bool similar : {false, true}) {
    for (const Positions* t : {static_cast<const Positions*>(nullptr), &f.normalizedTarget}) {
      const IdealComparison c = compareIdealMaps(backend(), mesh.faces, f.space.basePositions(), f.maps, t, similar);
      EXPECT_LT(c.maps, 1e-10) << "similar " << similar << ", target " << (t != nullptr);
      EXPECT_EQ(c.methodMismatches, 0);
      EXPECT_GT(c.largestRotation, 1e-2);  // the fits are not near the identity
    }
  }
}

TEST_F(VulkanIdealMaps, AgreeWithTheCpuOnFitsOfRandomlyMovedNonPlanarQuads) {
  const PolygonMesh mesh = generate::translationalSurface(12, 9);
  for (const unsigned seed : {1u, 2u, 3u}) {
    const Fitted f = fit(mesh, rotatedScaledAndPerturbed(mesh.vertices, 1.4, 0.02, seed));
    for (const bool similar : {false, true}) {
      const IdealComparison c =
          compareIdealMaps(backend(), mesh.faces, f.space.basePositions(), f.maps, &f.normalizedTarget, similar);
      EXPECT_LT(c.maps, 1e-10) << "seed " << seed << ", similar " << similar;
      EXPECT_EQ(c.methodMismatches, 0);
      EXPECT_GT(c.largestRotation, 0.1);
    }
  }
}

TEST_F(VulkanIdealMaps, FitsThroughThePlaneAtInfinityFallBackToCornerProcrustesAsOnTheCpu) {
  const PolygonMesh mesh = generate::hexagonalDome(2);
  const Fitted f = fit(mesh, rotatedScaledAndPerturbed(mesh.vertices, 0.8, 0.0, 4));
  const Positions& p = f.space.basePositions();
  // Every other face's fit changes weight sign across the face; the others stay the fits.
  std::vector<Eigen::Matrix4d> broken = f.maps;
  for (Index face = 0; face < mesh.faces.size(); face += 2) {
    const auto corners = mesh.faces[face];
    const Eigen::RowVector3d a = p.row(corners[0]);
    const Eigen::RowVector3d b = p.row(corners[3]);
    broken[face] = Eigen::Matrix4d::Identity();
    broken[face].block<3, 1>(0, 3) = 1e3 * (b - a).transpose();
    broken[face](3, 3) = 1.0 - 1e3 * (b - a).dot(0.5 * (a + b));
  }
  for (const bool similar : {false, true}) {
    const IdealComparison c = compareIdealMaps(backend(), mesh.faces, p, broken, &f.normalizedTarget, similar);
    EXPECT_LT(c.maps, 1e-10) << "similar " << similar;
    EXPECT_EQ(c.methodMismatches, 0);
    EXPECT_EQ(c.fallbacks, (mesh.faces.size() + 1) / 2);
  }
  // Without a target, a centroid at infinity is reported as on the CPU, and the operation of
  // projective/IdealMaps.h names the face.
  std::vector<Eigen::Matrix4d> atInfinity = f.maps;
  Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
  for (const Index v : mesh.faces[1]) centroid += p.row(v);
  centroid /= static_cast<double>(mesh.faces.degree(1));
  atInfinity[1] = Eigen::Matrix4d::Identity();
  atInfinity[1].block<3, 1>(0, 3) = Eigen::Vector3d(1.0, 0.0, 0.0);
  atInfinity[1](3, 3) = -centroid.x();  // w(centroid) = x - x = 0
  const IdealComparison none = compareIdealMaps(backend(), mesh.faces, p, atInfinity, nullptr, false);
  EXPECT_EQ(none.methodMismatches, 0);
  compute::IdealMaps gpu;
  backend().closestIdealMaps(mesh.faces, p, atInfinity, nullptr, false, gpu);
  EXPECT_EQ(gpu.methods[1], compute::IdealMapMethod::CentroidAtInfinity);
  try {
    projective::closestIdealMaps(backend(), f.space, atInfinity, projective::IdealMapKind::Rigid);
    ADD_FAILURE() << "expected Error(Numerical)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("face 1 "), std::string::npos) << e.what();
  }
}

TEST_F(VulkanIdealMaps, ARepeatedSourceAndTopologyStayOnTheDevice) {
  const PolygonMesh mesh = generate::translationalSurface(6, 7);
  const Fitted f = fit(mesh, rotatedScaledAndPerturbed(mesh.vertices, 1.1, 0.01, 5));
  compute::IdealMaps out;
  backend().closestIdealMaps(mesh.faces, f.space.basePositions(), f.maps, &f.normalizedTarget, true, out);
  const vk::TransferCounts before = context().transfers();
  backend().closestIdealMaps(mesh.faces, f.space.basePositions(), f.maps, &f.normalizedTarget, true, out);
  const vk::TransferCounts after = context().transfers();
  // Up: the fitted maps and the target; down: the ideal maps and the methods.
  const auto faces = static_cast<std::uint64_t>(mesh.faces.size());
  EXPECT_EQ(after.uploads - before.uploads, 2u);
  EXPECT_EQ(after.uploadedBytes - before.uploadedBytes,
            faces * 128u + static_cast<std::uint64_t>(mesh.vertices.size()) * 8u);
  EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, faces * (128u + 4u));
}

TEST_F(VulkanIdealMaps, TheFitsOfTheLastLocalStepAndTheirTargetAreNotUploadedAgain) {
  const PolygonMesh mesh = generate::translationalSurface(7, 6);
  const projective::ShapeSpace space(mesh);
  const Positions target = rotatedScaledAndPerturbed(mesh.vertices, 1.2, 0.01, 6);
  const Positions normalized = space.normalization().toNormalized(target);
  // A deformation's first iteration uploads the base mesh and topology to both kernels.
  compute::IdealMaps warm;
  backend().closestIdealMaps(mesh.faces, space.basePositions(),
                             projective::fitFaceMaps(backend(), space, mesh.vertices).fits.maps, nullptr, false, warm);
  // A later local step on this backend, then its ideal maps.
  const projective::LocalStepResult fit = projective::fitFaceMaps(backend(), space, target);
  const vk::TransferCounts before = context().transfers();
  const IdealComparison c = compareIdealMaps(backend(), mesh.faces, space.basePositions(), fit.fits.maps, &normalized, false);
  const vk::TransferCounts after = context().transfers();
  EXPECT_LT(c.maps, 1e-10);
  EXPECT_EQ(c.methodMismatches, 0);
  EXPECT_EQ(after.uploads - before.uploads, 0u);
  // Other maps than the fit's are uploaded, and the result is theirs.
  std::vector<Eigen::Matrix4d> other = fit.fits.maps;
  other[3](0, 1) += 0.05;
  const IdealComparison changed = compareIdealMaps(backend(), mesh.faces, space.basePositions(), other, &normalized, false);
  EXPECT_LT(changed.maps, 1e-10);
  EXPECT_EQ(context().transfers().uploadedBytes - after.uploadedBytes, static_cast<std::uint64_t>(mesh.faces.size()) * 128u);
}

TEST_F(VulkanIdealMaps, TheFusedLocalStepAgreesWithTheCpuAndBringsBackOnlyTheIdealMaps) {
  const PolygonMesh mesh = generate::translationalSurface(7, 6);
  const projective::ShapeSpace space(mesh);
  const auto faces = static_cast<std::uint64_t>(mesh.faces.size());
  for (const unsigned seed : {7u, 8u}) {
    const Positions target =
        space.normalization().toNormalized(rotatedScaledAndPerturbed(mesh.vertices, 1.3, 0.02, seed));
    for (const bool similar : {false, true}) {
      compute::IdealMaps cpu;
      compute::CpuBackend().fitIdealMaps(mesh.faces, space.basePositions(), target, similar, cpu);
      compute::IdealMaps warm;  // the base mesh and topology reach the device once
      backend().fitIdealMaps(mesh.faces, space.basePositions(), space.basePositions(), similar, warm);
      const vk::TransferCounts before = context().transfers();
      compute::IdealMaps gpu;
      backend().fitIdealMaps(mesh.faces, space.basePositions(), target, similar, gpu);
      const vk::TransferCounts after = context().transfers();
      double largest = 0.0, rotation = 0.0;
      for (Index f = 0; f < mesh.faces.size(); ++f) {
        largest = std::max(largest, (gpu.maps[f] - cpu.maps[f]).cwiseAbs().maxCoeff());
        rotation = std::max(rotation, (cpu.maps[f].topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity()).norm());
        EXPECT_EQ(gpu.methods[f], cpu.methods[f]) << "face " << f;
      }
      EXPECT_LT(largest, 1e-10) << "seed " << seed << ", similar " << similar;
      EXPECT_GT(rotation, 0.1);  // far from the identity: the comparison means something
      // Up: the target positions, once; down: the ideal maps and their methods, no fit.
      EXPECT_EQ(after.uploads - before.uploads, 1u);
      EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(target.size()) * 8u);
      EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, faces * (128u + 4u));
    }
  }
  // A separate fit and ideal-map call bring the fits back as well (maps, scales, residuals,
  // ranks): what the fused step saves.
  const Positions target = space.normalization().toNormalized(rotatedScaledAndPerturbed(mesh.vertices, 1.3, 0.02, 9));
  const vk::TransferCounts before = context().transfers();
  compute::ProjectiveFits fits;
  backend().fitProjectiveMaps(mesh.faces, space.basePositions(), target, fits);
  compute::IdealMaps separate;
  backend().closestIdealMaps(mesh.faces, space.basePositions(), fits.maps, &target, false, separate);
  const vk::TransferCounts after = context().transfers();
  EXPECT_EQ(after.downloadedBytes - before.downloadedBytes,
            faces * (128u + 4u) + faces * (128u + 8u + 4u) + static_cast<std::uint64_t>(mesh.faces.cornerCount()) * 8u);
}

TEST_F(VulkanIdealMaps, AGlobalStepOnTheIdealMapsJustComputedFormsItsLinearTermFromThemOnTheDevice) {
  const PolygonMesh mesh = generate::translationalSurface(6, 6);
  const projective::ShapeSpace space(mesh);
  std::vector<Index> fixed;
  for (Index v = 0; v <= 6; ++v) fixed.push_back(v);
  Positions at(fixed.size(), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(i) = mesh.vertices.row(fixed[i]);
  const Positions target = rotatedScaledAndPerturbed(mesh.vertices, 1.0, 0.02, 10);
  const Positions other = rotatedScaledAndPerturbed(mesh.vertices, 1.0, 0.02, 11);
  const auto ideal = projective::fittedIdealMaps(backend(), space, target, projective::IdealMapKind::Rigid);

  // The same step twice, each with a solver of its own: first after other ideal maps were
  // computed (q is uploaded), then right after these were (q is formed on the device).
  const auto solveAfter = [&](const Positions& last, projective::FaceMaps& maps) {
    projective::GlobalStep step(backend(), space, fixed);
    const auto latest = projective::fittedIdealMaps(backend(), space, last, projective::IdealMapKind::Rigid);
    const vk::TransferCounts before = context().transfers();
    const projective::GlobalStepInfo info = step.solve(ideal, at, maps);
    const vk::TransferCounts after = context().transfers();
    EXPECT_GT(info.admmIterations, 0);
    return std::pair{after.uploads - before.uploads, after.uploadedBytes - before.uploadedBytes};
  };
  projective::FaceMaps uploaded, formed;
  const auto [uploads, uploadedBytes] = solveAfter(other, uploaded);
  const auto [formedUploads, formedBytes] = solveAfter(target, formed);
  const auto qBytes = static_cast<std::uint64_t>(4 * mesh.faces.size() * 3) * sizeof(double);
  EXPECT_EQ(uploadedBytes - formedBytes, qBytes);
  EXPECT_EQ(uploads - formedUploads, 1u);
  // Bit for bit the same step.
  ASSERT_EQ(formed.maps.size(), uploaded.maps.size());
  for (std::size_t f = 0; f < formed.maps.size(); ++f) EXPECT_EQ(formed.maps[f], uploaded.maps[f]) << "face " << f;
}

TEST_F(VulkanIdealMaps, MapsKeptOnTheDeviceAgreeWithTheCpuAndOnlyTheirTalliesComeBack) {
  const PolygonMesh mesh = generate::hexagonalDome(2);  // hexagons: some corner-set fallbacks
  const projective::ShapeSpace space(mesh);
  const auto faces = static_cast<std::uint64_t>(mesh.faces.size());
  for (const unsigned seed : {21u, 22u}) {
    const Positions target =
        space.normalization().toNormalized(rotatedScaledAndPerturbed(mesh.vertices, 1.2, 0.05, seed));
    for (const bool similar : {false, true}) {
      compute::IdealMaps cpu;
      compute::CpuBackend().fitIdealMaps(mesh.faces, space.basePositions(), target, similar, cpu);
      compute::DeviceIdealMaps warm;  // the base mesh and topology reach the device once
      backend().fitIdealMapsOnDevice(mesh.faces, space.basePositions(), space.basePositions(), similar, warm);
      const vk::TransferCounts before = context().transfers();
      compute::DeviceIdealMaps kept;
      backend().fitIdealMapsOnDevice(mesh.faces, space.basePositions(), target, similar, kept);
      const vk::TransferCounts after = context().transfers();
      // Up: the target positions; down: three tallies, no map.
      EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(target.size()) * 8u);
      EXPECT_EQ(after.downloadedBytes - before.downloadedBytes, 12u);
      EXPECT_FALSE(kept.linearColumns.onHost());

      Index procrustes = 0;
      for (const auto method : cpu.methods) procrustes += method == compute::IdealMapMethod::CornerProcrustes;
      EXPECT_EQ(kept.cornerProcrustes, procrustes);
      EXPECT_EQ(kept.centroidsAtInfinity, 0);
      EXPECT_EQ(kept.firstCentroidAtInfinity, -1);

      const Eigen::MatrixXd& columns = kept.linearColumns.values();  // the one download of the maps
      EXPECT_EQ(context().transfers().downloadedBytes - after.downloadedBytes, faces * 128u);
      ASSERT_EQ(columns.rows(), static_cast<Eigen::Index>(4 * faces));
      double largest = 0.0;
      for (Index f = 0; f < mesh.faces.size(); ++f) {
        largest = std::max(largest, (columns.middleRows<4>(4 * f) - cpu.maps[f].leftCols<3>()).cwiseAbs().maxCoeff());
        EXPECT_EQ(cpu.maps[f].col(3), Eigen::Vector4d(0.0, 0.0, 0.0, 1.0));  // affine: nothing to keep there
      }
      EXPECT_LT(largest, 1e-10) << "seed " << seed << ", similar " << similar;
      EXPECT_EQ(kept.linearColumns.negated().values(), -columns);  // shares the copy: no download
    }
  }
}

TEST_F(VulkanIdealMaps, KeptMapsCannotBeReadOnceTheDeviceHasRewrittenThem) {
  const PolygonMesh mesh = generate::translationalSurface(4, 4);
  const projective::ShapeSpace space(mesh);
  const Positions first = rotatedScaledAndPerturbed(space.basePositions(), 1.0, 0.01, 1);
  const Positions second = rotatedScaledAndPerturbed(space.basePositions(), 1.0, 0.01, 2);
  compute::DeviceIdealMaps a, b;
  backend().fitIdealMapsOnDevice(mesh.faces, space.basePositions(), first, false, a);
  backend().fitIdealMapsOnDevice(mesh.faces, space.basePositions(), second, false, b);
  try {
    (void)a.linearColumns.values();
    ADD_FAILURE() << "expected Error(Usage)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
  }
  EXPECT_EQ(b.linearColumns.values().rows(), static_cast<Eigen::Index>(4 * mesh.faces.size()));  // the latest are still there
  // The CPU keeps its maps on the host.
  compute::DeviceIdealMaps host;
  compute::CpuBackend().fitIdealMapsOnDevice(mesh.faces, space.basePositions(), first, false, host);
  EXPECT_TRUE(host.linearColumns.onHost());
}

TEST_F(VulkanIdealMaps, AnAffineGlobalStepOnKeptMapsUploadsNoTargetsAndIsTheStepOnTheirValues) {
  const PolygonMesh mesh = generate::translationalSurface(4, 4);
  const projective::ShapeSpace space(mesh);
  std::vector<Index> fixed;
  for (Index v = 0; v <= 4; ++v) fixed.push_back(v);
  Positions at(fixed.size(), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(i) = mesh.vertices.row(fixed[i]);
  const Positions target = rotatedScaledAndPerturbed(mesh.vertices, 1.0, 0.02, 12);

  // The step on the kept maps, and a step of a solver of its own on their values, uploaded.
  const compute::DeviceMatrix kept =
      projective::fittedIdealMapsOnDevice(backend(), space, target, projective::IdealMapKind::Rigid);
  projective::FaceMaps onDevice, fromHost;
  vk::TransferCounts before = context().transfers();
  const projective::GlobalStepInfo a = projective::GlobalStep(backend(), space, fixed).solveAffine(kept, at, onDevice);
  const std::uint64_t keptUploads = context().transfers().uploadedBytes - before.uploadedBytes;
  EXPECT_FALSE(kept.onHost());  // nothing read the maps on the host
  const Eigen::MatrixXd values = kept.values();
  before = context().transfers();
  const projective::GlobalStepInfo b = projective::GlobalStep(backend(), space, fixed).solveAffine(values, at, fromHost);
  const vk::TransferCounts afterValues = context().transfers();
  EXPECT_GT(a.admmIterations, 0);
  const auto qBytes = static_cast<std::uint64_t>(values.size()) * sizeof(double);
  // The values' step uploads q (its x = -q is formed on the device either way).
  EXPECT_EQ((afterValues.uploadedBytes - before.uploadedBytes) - keptUploads, qBytes);
  EXPECT_EQ(a.initialViolation, b.initialViolation);
  EXPECT_EQ(a.admmIterations, b.admmIterations);
  ASSERT_EQ(onDevice.maps.size(), fromHost.maps.size());
  for (std::size_t f = 0; f < onDevice.maps.size(); ++f) EXPECT_EQ(onDevice.maps[f], fromHost.maps[f]) << "face " << f;

  // The result's columns can stay where the QP solved for them too: the same values, the
  // residuals measured there (the host's to rounding).
  compute::DeviceMatrix columns;
  projective::GlobalStep keeping(backend(), space, fixed);  // the columns live with its solver
  const projective::GlobalStepInfo c = keeping.solveAffine(kept, at, columns);
  EXPECT_FALSE(columns.onHost());
  const Eigen::MatrixXd& x = columns.values();
  for (std::size_t f = 0; f < onDevice.maps.size(); ++f) {
    EXPECT_EQ(x.middleRows<4>(4 * static_cast<Eigen::Index>(f)), onDevice.maps[f].leftCols<3>()) << "face " << f;
  }
  EXPECT_NEAR(c.constraintResidual, b.constraintResidual, 1e-15);
  EXPECT_NEAR(c.positionalResidual, b.positionalResidual, 1e-15);
  EXPECT_GT(c.constraintResidual, 0.0);
}

TEST_F(VulkanIdealMaps, TheFusedLocalStepOfATargetOfOtherSizeIsAUsageErrorOnBothBackends) {
  const PolygonMesh mesh = generate::cube();
  const Positions shortTarget = mesh.vertices.topRows(4);
  compute::IdealMaps out;
  for (compute::Backend* b : {static_cast<compute::Backend*>(&backend()), static_cast<compute::Backend*>(nullptr)}) {
    compute::CpuBackend cpu;
    compute::Backend& on = b ? *b : cpu;
    try {
      on.fitIdealMaps(mesh.faces, mesh.vertices, shortTarget, false, out);
      ADD_FAILURE() << on.name() << ": expected Error(Usage)";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage) << e.what();
    }
  }
}

TEST_F(VulkanIdealMaps, AMapCountOtherThanTheFacesOrATargetOfOtherSizeIsAUsageError) {
  const PolygonMesh mesh = generate::cube();
  std::vector<Eigen::Matrix4d> fewer(mesh.faces.size() - 1, Eigen::Matrix4d::Identity());
  compute::IdealMaps out;
  EXPECT_THROW(backend().closestIdealMaps(mesh.faces, mesh.vertices, fewer, nullptr, false, out), Error);
  EXPECT_THROW(compute::CpuBackend().closestIdealMaps(mesh.faces, mesh.vertices, fewer, nullptr, false, out), Error);
  const std::vector<Eigen::Matrix4d> maps(mesh.faces.size(), Eigen::Matrix4d::Identity());
  const Positions shortTarget = mesh.vertices.topRows(4);
  EXPECT_THROW(backend().closestIdealMaps(mesh.faces, mesh.vertices, maps, &shortTarget, false, out), Error);
  EXPECT_THROW(compute::CpuBackend().closestIdealMaps(mesh.faces, mesh.vertices, maps, &shortTarget, false, out),
               Error);
}

}  // namespace
}  // namespace plano::test
