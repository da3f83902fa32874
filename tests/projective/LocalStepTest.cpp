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

/// The points x H (row-vector convention), dehomogenized.
std::vector<Eigen::Vector3d> imagesUnder(const Eigen::Matrix4d& H, const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> images;
  for (const auto& x : points) {
    const Eigen::RowVector4d h = hom(x) * H;
    images.emplace_back(h.head<3>().transpose() / h[3]);
  }
  return images;
}

/// The mean of a fit's reciprocal scales over its corners (the fit's normalization: 1).
double meanReciprocalScale(const ProjectiveFit& fit) {
  double sum = 0.0;
  for (const double s : fit.reciprocalScales) sum += s;
  return sum / static_cast<double>(fit.reciprocalScales.size());
}

TEST(LocalFit, RecoversPerspectiveImagesOfQuadsPentagonsAndHexagonsExactly) {
  const Eigen::Matrix4d H = test::samplePerspective();
  for (int k : {4, 5, 6}) {
    const auto p = tiltedPolygon(k);
    const std::vector<Eigen::Vector3d> q = imagesUnder(H, p);
    const ProjectiveFit fit = fitProjectiveMap(p, q);
    EXPECT_LT(fit.residual, 1e-12) << k << "-gon";
    EXPECT_NEAR(meanReciprocalScale(fit), 1.0, 1e-14) << k << "-gon";
    // Scale factors: shat_i (q_i, 1) = (p_i, 1) T, and shat_i proportional to the true weights.
    const double ratio = fit.reciprocalScales[0] / hom(p[0]).dot(H.col(3));
    for (int i = 0; i < k; ++i) {
      const Eigen::RowVector4d image = hom(p[i]) * fit.map;
      EXPECT_LT((image - fit.reciprocalScales[i] * hom(q[i])).cwiseAbs().maxCoeff(), 1e-10) << k << "-gon corner " << i;
      EXPECT_NEAR(fit.reciprocalScales[i], ratio * hom(p[i]).dot(H.col(3)), 1e-10) << k << "-gon corner " << i;
    }
  }
}

/// Centroid of a corner set.
Eigen::Vector3d centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& x : points) c += x;
  return c / static_cast<double>(points.size());
}

/// The map in coordinates centred at the face centroids, T' = S_p^{-1} T S_q with
/// (p, 1) S_p = (p - c_p, 1), normalized to T'(3, 3) = 1.
Eigen::Matrix4d centredMap(const Eigen::Matrix4d& T, const Eigen::Vector3d& cp, const Eigen::Vector3d& cq) {
  Eigen::Matrix4d SpInverse = Eigen::Matrix4d::Identity();
  SpInverse.block<1, 3>(3, 0) = cp.transpose();
  Eigen::Matrix4d Sq = Eigen::Matrix4d::Identity();
  Sq.block<1, 3>(3, 0) = -cq.transpose();
  const Eigen::Matrix4d centred = SpInverse * T * Sq;
  return centred / centred(3, 3);
}

TEST(LocalFit, PicksTheSolutionClosestToTheIdentityForPlanarQuads) {
  const auto p = tiltedPolygon(4);
  // The identity itself when nothing moves.
  const ProjectiveFit same = fitProjectiveMap(p, p);
  EXPECT_LT((same.map - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-12);

  // "Closest to the identity" is measured in coordinates centred at each face's own
  // centroids (the fit is solved there, which excludes the collapsing solution and makes the
  // criterion independent of where the face sits), so the test looks at T' = S_p^{-1} T S_q.
  // There the source plane passes through the origin, its homogeneous normal is m = (n, 0),
  // and the null space holds the maps m u^T with u_3 = 0: T' - I is orthogonal to it,
  // (T' - I)[:, j] . m = 0 for j < 3. (Uncentred, the same statement held with
  // m = (n, -n.c) for the uncentred T; the two minimizers differ, as the Frobenius distance
  // to the identity is not invariant under translations.)
  const Eigen::Matrix4d H = test::samplePerspective();
  const std::vector<Eigen::Vector3d> q = imagesUnder(H, p);
  const ProjectiveFit fit = fitProjectiveMap(p, q);
  EXPECT_LT(fit.residual, 1e-12);
  EXPECT_NEAR(meanReciprocalScale(fit), 1.0, 1e-14);
  const Eigen::Vector3d cp = centroid(p), cq = centroid(q);
  const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  const Eigen::Vector4d m(n.x(), n.y(), n.z(), 0.0);
  const Eigen::Matrix4d centred = centredMap(fit.map, cp, cq);
  const Eigen::Matrix4d D = centred - Eigen::Matrix4d::Identity();
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(D.col(j).dot(m), 0.0, 1e-10) << "column " << j;
  // And H itself solves the same equations but is farther away.
  EXPECT_LT(D.norm(), (centredMap(H, cp, cq) - Eigen::Matrix4d::Identity()).norm());
}

TEST(LocalFit, PerturbedPentagonsAndHexagonsDoNotCollapse) {
  // Five or six corners over-determine a planar homography. Uncentred, the equations had the
  // exact solution T = n_h r^T on the homogeneous source plane n_h, collapsing the face
  // (residual ~1e-16, all reciprocal scales ~0). Centred fits must give the least-squares
  // map instead: scales near 1 (mean reciprocal scale 1) and a residual of the order of the
  // perturbation.
  const Eigen::Matrix4d H = test::samplePerspective();
  for (int k : {5, 6}) {
    const auto p = tiltedPolygon(k);
    for (bool perspective : {false, true}) {
      std::vector<Eigen::Vector3d> q;
      for (int i = 0; i < k; ++i) {
        Eigen::Vector3d x = p[i];
        if (perspective) {
          const Eigen::RowVector4d h = hom(x) * H;
          x = h.head<3>().transpose() / h[3];
        }
        // In-plane-ish perturbation of size ~0.01 (the polygon has radius ~0.4).
        q.push_back(x + 0.01 * Eigen::Vector3d(std::sin(5.0 * i + k), std::cos(3.0 * i), std::sin(7.0 * i + 1.0)));
      }
      const ProjectiveFit fit = fitProjectiveMap(p, q);
      EXPECT_GT(fit.residual, 1e-5) << k << "-gon";
      EXPECT_LT(fit.residual, 0.02) << k << "-gon";
      EXPECT_NEAR(meanReciprocalScale(fit), 1.0, 1e-12) << k << "-gon";
      for (int i = 0; i < k; ++i) {
        const double s = fit.reciprocalScales[i];
        EXPECT_GT(s, 0.5) << k << "-gon corner " << i;
        EXPECT_LT(s, 2.0) << k << "-gon corner " << i;
        if (!perspective) {
          EXPECT_NEAR(fit.reciprocalScales[i], 1.0, 0.2) << k << "-gon corner " << i;
        }
      }
    }
  }
}

TEST(LocalFit, AMapThatSendsTheOriginToInfinityKeepsUnitMeanScaleAndExactCorners) {
  // A small square in the plane z = 0 (which holds the origin), 0.4 from the origin, and its
  // image under a map whose weight vanishes at the origin: shat(p) = 2.5 x. The paper's
  // T(3, 3) = 1 does not exist for this face (T(3, 3) = shat(origin) = 0).
  const std::vector<Eigen::Vector3d> p = {{0.39, -0.01, 0.0}, {0.41, -0.01, 0.0}, {0.41, 0.01, 0.0}, {0.39, 0.01, 0.0}};
  Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
  H.col(3) = Eigen::Vector4d(2.5, 0.0, 0.0, 0.0);
  H(3, 0) = 0.1;
  const std::vector<Eigen::Vector3d> q = imagesUnder(H, p);
  const ProjectiveFit fit = fitProjectiveMap(p, q);
  EXPECT_LT(fit.residual, 1e-12);
  EXPECT_NEAR(meanReciprocalScale(fit), 1.0, 1e-12);
  EXPECT_NEAR(fit.map(3, 3), 0.0, 1e-10);
  EXPECT_LT(fit.map.cwiseAbs().maxCoeff(), 10.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(fit.reciprocalScales[i], 2.5 * p[i].x(), 1e-10) << "corner " << i;
    const Eigen::RowVector4d image = hom(p[i]) * fit.map;
    EXPECT_LT((image - fit.reciprocalScales[i] * hom(q[i])).cwiseAbs().maxCoeff(), 1e-12) << "corner " << i;
  }
}

TEST(LocalFit, FitsDoNotDependOnWhereTheFaceSits) {
  // Translating source and target conjugates the map; the reciprocal scales, normalized on
  // the face itself, do not change.
  const auto p = tiltedPolygon(6);
  std::vector<Eigen::Vector3d> q;
  for (int i = 0; i < 6; ++i) q.push_back(1.1 * p[i] + 0.02 * Eigen::Vector3d(std::cos(2.0 * i), std::sin(i), 0.3));
  const Eigen::Vector3d a(0.3, -0.1, 0.2), b(-0.2, 0.25, 0.1);
  std::vector<Eigen::Vector3d> pMoved, qMoved;
  for (int i = 0; i < 6; ++i) {
    pMoved.push_back(p[i] + a);
    qMoved.push_back(q[i] + b);
  }
  const ProjectiveFit fit = fitProjectiveMap(p, q);
  const ProjectiveFit moved = fitProjectiveMap(pMoved, qMoved);
  EXPECT_NEAR(moved.residual, fit.residual, 1e-12);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(moved.reciprocalScales[i], fit.reciprocalScales[i], 1e-10);
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
