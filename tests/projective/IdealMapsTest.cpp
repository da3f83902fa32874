#include "projective/IdealMaps.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <random>

#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"
#include "projective/LocalStep.h"
#include "projective/ProjectiveTestHelpers.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

/// Orthogonal polar factor by Newton's iteration X <- (X + X^-T) / 2: independent of the SVD.
Eigen::Matrix3d polarByNewton(const Eigen::Matrix3d& M) {
  Eigen::Matrix3d X = M;
  for (int i = 0; i < 100; ++i) X = 0.5 * (X + X.inverse().transpose());
  return X;
}

TEST(ClosestRotations, MatchPolarDecompositionOnRandomMatrices) {
  compute::CpuBackend backend;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Matrix3d> matrices;
  while (matrices.size() < 200) {
    Eigen::Matrix3d M;
    for (int i = 0; i < 9; ++i) M.data()[i] = uniform(rng);
    if (std::abs(M.determinant()) > 1e-2) matrices.push_back(M);
  }
  std::vector<Eigen::Matrix3d> rotations(matrices.size());
  std::vector<Eigen::Vector3d> singular(matrices.size());
  backend.closestRotations(matrices, rotations, singular);
  int reflected = 0;
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    const Eigen::Matrix3d& R = rotations[i];
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    if (matrices[i].determinant() > 0.0) {
      EXPECT_LT((R - polarByNewton(matrices[i])).cwiseAbs().maxCoeff(), 1e-10) << "matrix " << i;
    } else {
      // No proper rotation is the polar factor; R must still beat nearby rotations.
      ++reflected;
      const double best = (matrices[i] - R).norm();
      for (int k = 0; k < 20; ++k) {
        const Eigen::Matrix3d nearby =
            R * Eigen::AngleAxisd(0.05, Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)).normalized())
                    .toRotationMatrix();
        EXPECT_LE(best, (matrices[i] - nearby).norm() + 1e-12);
      }
    }
  }
  EXPECT_GT(reflected, 0);
}

class IdealMapsOfMovedMesh : public ::testing::Test {
 protected:
  /// World positions of the base mesh under x -> scale * x R + t.
  static Positions moved(const Positions& x, double scale) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.4).normalized()).toRotationMatrix();
    return ((scale * x * R).rowwise() + Eigen::RowVector3d(0.5, -1.0, 2.0)).eval();
  }
  compute::CpuBackend backend;
  PolygonMesh mesh = generate::hexagonalDome(2);
};

TEST_F(IdealMapsOfMovedMesh, RigidMotionIsReproducedExactly) {
  const ShapeSpace space(mesh);
  const Positions target = moved(mesh.vertices, 1.0);
  const LocalStepResult fit = fitFaceMaps(backend, space, target);
  const auto rigid = closestIdealMaps(backend, space, fit.fits.maps, IdealMapKind::Rigid);
  EXPECT_LT(test::maxAbsDifference(space.positions(rigid), target), 1e-10);
  for (const auto& A : rigid) EXPECT_EQ(A.col(3), Eigen::Vector4d(0, 0, 0, 1));
}

TEST_F(IdealMapsOfMovedMesh, SimilarityKeepsTheScaleAndRigidDropsIt) {
  const ShapeSpace space(mesh);
  const Positions target = moved(mesh.vertices, 1.7);
  const LocalStepResult fit = fitFaceMaps(backend, space, target);
  const auto similar = closestIdealMaps(backend, space, fit.fits.maps, IdealMapKind::Similar);
  EXPECT_LT(test::maxAbsDifference(space.positions(similar), target), 1e-10);
  const auto rigid = closestIdealMaps(backend, space, fit.fits.maps, IdealMapKind::Rigid);
  for (Index f = 0; f < space.faceCount(); ++f) {
    const Eigen::Matrix3d L = rigid[f].topLeftCorner<3, 3>();
    EXPECT_LT((L.transpose() * L - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-10) << "face " << f;
    EXPECT_NEAR(similar[f].block(0, 0, 3, 3).determinant(), 1.7 * 1.7 * 1.7, 1e-9) << "face " << f;
  }
}

TEST_F(IdealMapsOfMovedMesh, PerspectiveFitsGiveAffineTargets) {
  const ShapeSpace space(mesh);
  const Positions target =
      space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), test::samplePerspective()));
  const LocalStepResult fit = fitFaceMaps(backend, space, target);
  for (IdealMapKind kind : {IdealMapKind::Rigid, IdealMapKind::Similar}) {
    const auto ideal = closestIdealMaps(backend, space, fit.fits.maps, kind);
    for (const auto& A : ideal) {
      EXPECT_EQ(A.col(3), Eigen::Vector4d(0, 0, 0, 1));
      EXPECT_GT(A.block(0, 0, 3, 3).determinant(), 0.0);
    }
  }
}

TEST_F(IdealMapsOfMovedMesh, DegenerateFitsFallBackToCornerProcrustes) {
  const ShapeSpace space(mesh);
  const Positions target = moved(mesh.vertices, 1.0);
  // Fits whose weights change sign across every face (a face through the plane at infinity).
  std::vector<Eigen::Matrix4d> broken(space.faceCount(), Eigen::Matrix4d::Identity());
  for (Index f = 0; f < space.faceCount(); ++f) {
    const auto face = space.faces()[f];
    const Eigen::RowVector3d a = space.basePositions().row(face[0]);
    const Eigen::RowVector3d b = space.basePositions().row(face[3]);
    broken[f].block<3, 1>(0, 3) = 1e3 * (b - a).transpose();
    broken[f](3, 3) = 1.0 - 1e3 * (b - a).dot(0.5 * (a + b));
  }
  const Positions normalizedTarget = space.normalization().toNormalized(target);
  Index fallbacks = 0;
  const auto rigid = closestIdealMaps(backend, space, broken, IdealMapKind::Rigid, &normalizedTarget, &fallbacks);
  EXPECT_EQ(fallbacks, space.faceCount());
  EXPECT_LT(test::maxAbsDifference(space.positions(rigid), target), 1e-10);
}

}  // namespace
}  // namespace plano::projective
