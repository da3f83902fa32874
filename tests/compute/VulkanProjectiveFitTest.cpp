// Vulkan batched projective fits against the CPU reference (LocalFit): maps, reciprocal
// scales, residuals and ranks to 1e-10 on well-conditioned faces.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "compute/KernelComparisons.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

/// A projective map in the row-vector convention that keeps w > 0 on the unit box.
Eigen::Matrix4d mildProjectiveMap() {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() * 1.2;
  T.block<1, 3>(3, 0) << 0.1, -0.2, 0.05;  // translation
  T.block<3, 1>(0, 3) << 0.08, -0.05, 0.03;  // perspective
  return T;
}

Positions applyMap(const Positions& points, const Eigen::Matrix4d& T) {
  Positions out(points.rows(), 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::RowVector4d h = Eigen::RowVector4d(points(i, 0), points(i, 1), points(i, 2), 1.0) * T;
    out.row(i) = h.head<3>() / h[3];
  }
  return out;
}

class VulkanProjectiveFit : public VulkanTest {};

TEST_F(VulkanProjectiveFit, IdentityTargetGivesIdentityMapsOnPlanarQuads) {
  const PolygonMesh mesh = generate::translationalSurface(6, 5);
  compute::ProjectiveFits fits;
  backend().fitProjectiveMaps(mesh.faces, mesh.vertices, mesh.vertices, fits);
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    EXPECT_LT((fits.maps[f] - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-12) << "face " << f;
  }
  expectFitAgreement(compareFits(backend(), mesh.faces, mesh.vertices, mesh.vertices));
}

TEST_F(VulkanProjectiveFit, MatchesCpuOnProjectivelyMappedQuads) {
  const PolygonMesh mesh = generate::surfaceOfRevolution(12, 5, 0.5, 1.0);
  const FitComparison c = compareFits(backend(), mesh.faces, mesh.vertices, applyMap(mesh.vertices, mildProjectiveMap()));
  expectFitAgreement(c);
}

TEST_F(VulkanProjectiveFit, MatchesCpuOnPerturbedQuads) {
  // After projection onto their planes, four corners always admit an exact map.
  const PolygonMesh mesh = generate::translationalSurface(5, 5);
  const Positions target = perturbed(applyMap(mesh.vertices, mildProjectiveMap()), 0.02, 3);
  expectFitAgreement(compareFits(backend(), mesh.faces, mesh.vertices, target));
}

TEST_F(VulkanProjectiveFit, MatchesCpuOnPerturbedHexagons) {
  // Six corners over-determine a planar homography. Both backends fit in face-centred
  // coordinates, which excludes the degenerate exact fit that collapses the face (all
  // reciprocal scales ~0): they must agree on the least-squares maps, whose residuals are of
  // the order of the perturbation and whose reciprocal scales stay near 1.
  const PolygonMesh dome = generate::hexagonalDome(3);
  const Positions target = perturbed(dome.vertices, 0.01, 9);
  const FitComparison c = compareFits(backend(), dome.faces, dome.vertices, target);
  expectFitAgreement(c);
  EXPECT_GT(c.largestResidual, 1e-5);
  compute::ProjectiveFits gpu;
  backend().fitProjectiveMaps(dome.faces, dome.vertices, target, gpu);
  for (Index f = 0; f < dome.faceCount(); ++f) {
    // Reciprocal scales in face-centred coordinates, shat'_i = shat_i T'(3, 3) with
    // T' = S_p^{-1} T S_q: mean 1 and none near 0 (no collapse).
    const auto face = dome.faces[f];
    Eigen::RowVector3d cp = Eigen::RowVector3d::Zero(), cq = Eigen::RowVector3d::Zero();
    for (Index v : face) {
      cp += dome.vertices.row(v);
      cq += target.row(v);
    }
    cp /= static_cast<double>(face.size());
    cq /= static_cast<double>(face.size());
    Eigen::Matrix4d SpInverse = Eigen::Matrix4d::Identity(), Sq = Eigen::Matrix4d::Identity();
    SpInverse.block<1, 3>(3, 0) = cp;
    Sq.block<1, 3>(3, 0) = -cq;
    const double centredScale = (SpInverse * gpu.maps[f] * Sq)(3, 3);
    double mean = 0.0;
    for (std::size_t i = 0; i < face.size(); ++i) {
      const double s = gpu.reciprocalScales[static_cast<std::size_t>(dome.faces.offsets()[f]) + i] / centredScale;
      mean += s;
      EXPECT_GT(s, 0.5) << "face " << f;
      EXPECT_LT(s, 2.0) << "face " << f;
    }
    EXPECT_NEAR(mean / static_cast<double>(face.size()), 1.0, 1e-10) << "face " << f;
  }
}

TEST_F(VulkanProjectiveFit, MatchesCpuOnPentagonsAndHexagons) {
  const PolygonMesh dodecahedron = generate::dodecahedron();
  expectFitAgreement(compareFits(backend(), dodecahedron.faces, dodecahedron.vertices,
                          perturbed(applyMap(dodecahedron.vertices, mildProjectiveMap()), 0.01, 5)));
  const PolygonMesh dome = generate::hexagonalDome(3);
  expectFitAgreement(compareFits(backend(), dome.faces, dome.vertices, applyMap(dome.vertices, mildProjectiveMap())));
}

TEST_F(VulkanProjectiveFit, MatchesCpuOnRandomTriangles) {
  // Triangles are not projected (always planar) and give 9 equations in 15 unknowns.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  PolygonMesh mesh;
  mesh.vertices.resize(60, 3);
  for (Index i = 0; i < mesh.vertices.size(); ++i) mesh.vertices.data()[i] = u(rng);
  for (Index f = 0; f < 20; ++f) mesh.faces.addFace({3 * f, 3 * f + 1, 3 * f + 2});
  expectFitAgreement(compareFits(backend(), mesh.faces, mesh.vertices, perturbed(mesh.vertices, 0.05, 2)));
}

TEST_F(VulkanProjectiveFit, ARepeatedSourceAndTopologyStayOnTheDeviceAndChangedOnesAreUploaded) {
  const PolygonMesh mesh = generate::translationalSurface(5, 5);
  const Positions first = applyMap(mesh.vertices, mildProjectiveMap());
  const Positions second = perturbed(first, 0.02, 3);
  compute::ProjectiveFits fits;
  backend().fitProjectiveMaps(mesh.faces, mesh.vertices, first, fits);
  const vk::TransferCounts before = context().transfers();
  expectFitAgreement(compareFits(backend(), mesh.faces, mesh.vertices, second));
  const vk::TransferCounts after = context().transfers();
  EXPECT_EQ(after.uploads - before.uploads, 1u);  // the targets only
  EXPECT_EQ(after.uploadedBytes - before.uploadedBytes, static_cast<std::uint64_t>(mesh.vertices.size()) * 8u);
  // A new source, then a new topology, are uploaded, and the fits are theirs.
  expectFitAgreement(compareFits(backend(), mesh.faces, first, second));
  const PolygonMesh other = generate::translationalSurface(4, 6);
  expectFitAgreement(compareFits(backend(), other.faces, other.vertices, applyMap(other.vertices, mildProjectiveMap())));
}

TEST_F(VulkanProjectiveFit, MismatchedPositionArraysAreAUsageError) {
  const PolygonMesh mesh = generate::cube();
  Positions fewer = mesh.vertices.topRows(4);
  compute::ProjectiveFits fits;
  EXPECT_THROW(backend().fitProjectiveMaps(mesh.faces, mesh.vertices, fewer, fits), Error);
}

}  // namespace
}  // namespace plano::test
