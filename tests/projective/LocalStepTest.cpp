#include "projective/LocalStep.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/LocalFit.h"
#include "projective/ProjectiveTestHelpers.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

/// A convex planar k-gon of radius ~0.4 in a tilted plane away from the origin.
std::vector<Eigen::Vector3d> tiltedPolygon(int k) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < k; ++i) {
    const double t = 2.0 * std::numbers::pi * i / k + 0.1 * std::sin(3.0 * i);
    const double r = 0.4 * (1.0 + 0.15 * std::cos(2.0 * i));
    points.push_back(R * Eigen::Vector3d(r * std::cos(t), r * std::sin(t), 0.0) + Eigen::Vector3d(0.1, -0.2, 0.3));
  }
  return points;
}

Eigen::RowVector4d hom(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z(), 1.0}; }

TEST(LocalFit, RecoversPerspectiveImagesOfQuadsPentagonsAndHexagonsExactly) {
  const Eigen::Matrix4d H = test::samplePerspective();
  for (int k : {4, 5, 6}) {
    const auto p = tiltedPolygon(k);
    std::vector<Eigen::Vector3d> q;
    for (const auto& x : p) {
      const Eigen::RowVector4d h = hom(x) * H;
      q.emplace_back(h.head<3>().transpose() / h[3]);
    }
    const ProjectiveFit fit = fitProjectiveMap(p, q);
    EXPECT_LT(fit.residual, 1e-12) << k << "-gon";
    EXPECT_EQ(fit.map(3, 3), 1.0);
    // Scale factors: shat_i (q_i, 1) = (p_i, 1) T, and shat_i proportional to the true weights.
    const double ratio = fit.reciprocalScales[0] / hom(p[0]).dot(H.col(3));
    for (int i = 0; i < k; ++i) {
      const Eigen::RowVector4d image = hom(p[i]) * fit.map;
      EXPECT_LT((image - fit.reciprocalScales[i] * hom(q[i])).cwiseAbs().maxCoeff(), 1e-10) << k << "-gon corner " << i;
      EXPECT_NEAR(fit.reciprocalScales[i], ratio * hom(p[i]).dot(H.col(3)), 1e-10) << k << "-gon corner " << i;
    }
  }
}

TEST(LocalFit, PicksTheSolutionClosestToTheIdentityForPlanarQuads) {
  const auto p = tiltedPolygon(4);
  // The identity itself when nothing moves.
  const ProjectiveFit same = fitProjectiveMap(p, p);
  EXPECT_LT((same.map - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-12);

  // Otherwise T - I is orthogonal to the null space, which for a plane with homogeneous
  // normal m = (n, -n.c) holds the maps m u^T with u_3 = 0: (T - I)[:, j] . m = 0, j < 3.
  const Eigen::Matrix4d H = test::samplePerspective();
  std::vector<Eigen::Vector3d> q;
  for (const auto& x : p) {
    const Eigen::RowVector4d h = hom(x) * H;
    q.emplace_back(h.head<3>().transpose() / h[3]);
  }
  const ProjectiveFit fit = fitProjectiveMap(p, q);
  const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  const Eigen::Vector4d m(n.x(), n.y(), n.z(), -n.dot(p[0]));
  const Eigen::Matrix4d D = fit.map - Eigen::Matrix4d::Identity();
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(D.col(j).dot(m), 0.0, 1e-10) << "column " << j;
  // And H itself (scaled to H(3,3) = 1) solves the same equations but is farther away.
  EXPECT_LT((fit.map - Eigen::Matrix4d::Identity()).norm(), (H / H(3, 3) - Eigen::Matrix4d::Identity()).norm());
}

TEST(LocalStep, BatchedFitIsExactOnProjectiveImagesOfPolyhedralMeshes) {
  compute::CpuBackend backend;
  for (const PolygonMesh& mesh :
       {generate::translationalSurface(5, 4), generate::dodecahedron(), generate::hexagonalDome(2)}) {
    const ShapeSpace space(mesh);
    const Positions target =
        space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), test::samplePerspective()));
    const LocalStepResult result = fitFaceMaps(backend, space, target);
    EXPECT_LT(result.maxResidual, 1e-10);
    EXPECT_EQ(result.nonPositiveScales, 0);
    // Every face's own map sends its corners onto the target: compatible maps.
    EXPECT_LT(test::maxAbsDifference(space.positions(result.fits.maps), target), 1e-10);
    EXPECT_LT(space.maxCornerDisagreement(result.fits.maps), 1e-10);
  }
}

TEST(LocalStep, RejectsTargetsOfTheWrongSize) {
  compute::CpuBackend backend;
  const ShapeSpace space(generate::cube());
  EXPECT_THROW(fitFaceMaps(backend, space, Positions::Zero(7, 3)), Error);
}

}  // namespace
}  // namespace plano::projective
