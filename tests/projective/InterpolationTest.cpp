#include "projective/Interpolation.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "projective/Deformation.h"
#include "projective/ProjectiveTestHelpers.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

TEST(MapFactors, FactorAndRecombineAnyOrientationPreservingMap) {
  const Eigen::Matrix4d T = test::samplePerspective() / test::samplePerspective()(3, 3);
  const MapFactors f = factorMap(T);
  EXPECT_LT((f.stretch - f.stretch.transpose()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(f.stretch).eigenvalues().minCoeff(), 0.0);
  EXPECT_NEAR(f.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((interpolatedMap(f, 1.0) - T).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((interpolatedMap(f, 0.0) - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(MapFactors, PureRotationInterpolatesByAngle) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(1.2, axis).toRotationMatrix();
  const Eigen::Matrix4d half = interpolatedMap(factorMap(T), 0.5);
  EXPECT_LT((half.topLeftCorner<3, 3>() - Eigen::AngleAxisd(0.6, axis).toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MapFactors, ReflectionIsANumericalError) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(0, 0) = -1.0;
  EXPECT_THROW(factorMap(T), Error);
}

class InterpolationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    a = generate::translationalSurface(8, 8);
    PositionalConstraints c;
    for (Index i = 0; i <= 8; ++i) c.fixed.push_back(i * 9);
    c.handles.push_back({80, a.vertices.row(80).transpose() + Eigen::Vector3d(0.1, 0.1, 0.4)});
    b = deform(backend, a, c).mesh;
  }
  compute::CpuBackend backend;
  PolygonMesh a;
  PolygonMesh b;
};

TEST_F(InterpolationTest, EndpointsAreTheInputMeshes) {
  Interpolation interpolation(backend, a, b);
  EXPECT_LT(test::maxAbsDifference(interpolation.at(0.0).vertices, a.vertices), 1e-8);
  EXPECT_LT(test::maxAbsDifference(interpolation.at(1.0).vertices, b.vertices), 1e-8);
}

TEST_F(InterpolationTest, StaysPolyhedralBetweenAndBeyond) {
  Interpolation interpolation(backend, a, b);
  for (double t : {0.25, 0.5, 0.75, 1.5, -1.0}) {
    GlobalStepInfo info;
    const PolygonMesh m = interpolation.at(t, &info);
    EXPECT_LT(planarityStats(m).max, 1e-8) << "t = " << t;
    EXPECT_EQ(info.epsilon, 0.0) << "t = " << t;
    // Between A and B, not collapsed: near the straight blend of the two.
    const Positions blend = (1.0 - t) * a.vertices + t * b.vertices;
    EXPECT_LT(test::maxAbsDifference(m.vertices, blend), 0.15 * std::max(1.0, std::abs(t))) << "t = " << t;
  }
}

TEST_F(InterpolationTest, ProjectivelyRelatedMeshesInterpolateOnPolyhedralMeshes) {
  const ShapeSpace space(a);
  PolygonMesh warped = a;
  warped.vertices = space.normalization().toWorld(test::applyProjectiveMap(space.basePositions(), test::samplePerspective()));
  Interpolation interpolation(backend, a, warped);
  EXPECT_LT(test::maxAbsDifference(interpolation.at(1.0).vertices, warped.vertices), 1e-8);
  EXPECT_LT(planarityStats(interpolation.at(0.5)).max, 1e-8);
}

TEST_F(InterpolationTest, RejectsMeshesOfDifferentTopology) {
  PolygonMesh other = generate::translationalSurface(8, 7);
  EXPECT_THROW(Interpolation(backend, a, other), Error);
  PolygonMesh flipped = a;
  flipped.faces = FaceList();
  for (Index f = 0; f < a.faceCount(); ++f) {
    std::vector<Index> face(a.faces[f].begin(), a.faces[f].end());
    if (f == 5) std::reverse(face.begin(), face.end());
    flipped.faces.addFace(std::span<const Index>(face));
  }
  try {
    Interpolation(backend, a, flipped);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("face 5"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plano::projective
