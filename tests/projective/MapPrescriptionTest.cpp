#include "projective/MapPrescription.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "projective/UniformScaling.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

PositionalConstraints fixedColumns(Index n) {
  // Vertices (i, 0) and (i, n) of an n x n translational grid.
  PositionalConstraints c;
  for (Index i = 0; i <= n; ++i) {
    c.fixed.push_back(i * (n + 1));
    c.fixed.push_back(i * (n + 1) + n);
  }
  return c;
}

class MapPrescriptionTest : public ::testing::Test {
 protected:
  compute::CpuBackend backend;
  PolygonMesh grid = generate::translationalSurface(8, 8);
};

TEST_F(MapPrescriptionTest, IdentityPrescriptionChangesNothing) {
  for (PrescribedMapKind kind : {PrescribedMapKind::Rotation, PrescribedMapKind::PerspectiveWarp,
                                 PrescribedMapKind::UniformScale}) {
    MapPrescription identity;  // angle 0, strength 0, scale 1
    identity.kind = kind;
    identity.pivot = Pivot::FaceCentroid;
    const PrescriptionResult r = prescribeMaps(backend, grid, identity, {}, fixedColumns(8));
    EXPECT_LT(test::maxAbsDifference(r.mesh.vertices, grid.vertices), 1e-14);
    EXPECT_EQ(r.info.status, GlobalStepStatus::Unchanged);
  }
}

TEST_F(MapPrescriptionTest, GlobalRotationOfAnUnconstrainedMeshRotatesIt) {
  const PolygonMesh mesh = generate::hexagonalDome(2);
  MapPrescription rotation;
  rotation.kind = PrescribedMapKind::Rotation;
  rotation.axis = Eigen::Vector3d(1, 1, 0);
  rotation.angle = 0.8;
  rotation.pivot = Pivot::Point;
  rotation.point = Eigen::Vector3d(0.3, -0.2, 0.5);
  const PrescriptionResult r = prescribeMaps(backend, mesh, rotation, {}, {});
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::RowVector3d c = rotation.point.transpose();
  const Positions expected = (((mesh.vertices.rowwise() - c) * R.transpose()).rowwise() + c).eval();
  EXPECT_LT(test::maxAbsDifference(r.mesh.vertices, expected), 1e-10);
}

TEST_F(MapPrescriptionTest, PerFaceRotationsWithFixedColumnsStayPlanarAndKeepTheColumns) {
  MapPrescription rotation;
  rotation.kind = PrescribedMapKind::Rotation;
  rotation.axis = Eigen::Vector3d::UnitY();
  rotation.angle = 0.5;
  rotation.pivot = Pivot::FaceCentroid;
  const PositionalConstraints fixed = fixedColumns(8);
  const PrescriptionResult r = prescribeMaps(backend, grid, rotation, {}, fixed);
  EXPECT_EQ(r.info.epsilon, 0.0);
  EXPECT_LT(r.maxPlanarity, 1e-8);
  EXPECT_GT(test::maxAbsDifference(r.mesh.vertices, grid.vertices), 1e-2);
  for (Index v : fixed.fixed) EXPECT_LT((r.mesh.vertices.row(v) - grid.vertices.row(v)).norm(), 1e-9) << v;
}

TEST_F(MapPrescriptionTest, WarpTurnsABoxIntoAFrustum) {
  // One shared perspective map on a cube: the face at +x shrinks, the face at -x grows.
  const PolygonMesh cube = generate::cube(2.0);
  MapPrescription warp;
  warp.kind = PrescribedMapKind::PerspectiveWarp;
  warp.axis = Eigen::Vector3d::UnitX();
  warp.strength = 0.5;
  const PrescriptionResult r = prescribeMaps(backend, cube, warp, {}, {});
  EXPECT_LT(r.maxPlanarity, 1e-10);
  double farSpan = 0.0;
  double nearSpan = 0.0;
  for (Index v = 0; v < cube.vertexCount(); ++v) {
    double& span = cube.vertices(v, 0) > 0.0 ? farSpan : nearSpan;
    span = std::max(span, std::abs(r.mesh.vertices(v, 1)));
  }
  EXPECT_LT(farSpan, 0.9);
  EXPECT_GT(nearSpan, 1.1);
}

TEST_F(MapPrescriptionTest, UnitScalingIsTheIdentityAndInterpolatedScalingsStayPlanar) {
  const UniformScalingFamily family(backend, grid, Pivot::MeshCentre, {}, fixedColumns(8));
  EXPECT_LT(test::maxAbsDifference(family.mesh(1.0).vertices, grid.vertices), 1e-12);
  double previous = 0.0;
  for (double t : {0.0, 0.25, 0.5, 0.75, 1.5, 2.0}) {
    const PolygonMesh m = family.mesh(t);
    EXPECT_LT(planarityStats(m).max, 1e-8) << "t = " << t;
    const double change = test::maxAbsDifference(m.vertices, grid.vertices);
    if (t != 0.0) {
      EXPECT_GT(change, 0.0) << "t = " << t;
    }
    if (t == 0.5) {
      EXPECT_LT(change, previous) << "deflation shrinks with t -> 1";
    }
    previous = change;
  }
  // The interpolated maps equal a direct projection of diag(t, t, t, 1).
  MapPrescription half;
  half.kind = PrescribedMapKind::UniformScale;
  half.scale = 0.5;
  const PrescriptionResult direct = prescribeMaps(backend, grid, half, {}, fixedColumns(8));
  EXPECT_LT(test::maxAbsDifference(direct.mesh.vertices, family.mesh(0.5).vertices), 1e-7);
}

TEST_F(MapPrescriptionTest, SelectedFacesOnlyAndBadSelectionsAreRejected) {
  const ShapeSpace space(grid);
  MapPrescription scale;
  scale.kind = PrescribedMapKind::UniformScale;
  scale.scale = 2.0;
  const auto targets = prescribedTargets(space, scale, {3, 7});
  for (Index f = 0; f < space.faceCount(); ++f) {
    EXPECT_EQ(targets[f] == Eigen::Matrix4d::Identity(), f != 3 && f != 7) << "face " << f;
  }
  EXPECT_THROW(prescribedTargets(space, scale, {64}), Error);
  MapPrescription zeroAxis;
  zeroAxis.axis = Eigen::Vector3d::Zero();
  EXPECT_THROW(prescribedTargets(space, zeroAxis), Error);
}

}  // namespace
}  // namespace plano::projective
