#include "projective/MapPrescription.h"

#include <Eigen/Geometry>
#include <string>

#include "core/Error.h"
#include "mesh/Planarity.h"
#include "projective/LocalStep.h"

namespace plano::projective {
namespace {

/// (x, 1) -> (x + v, 1) in the row-vector convention.
Eigen::Matrix4d translation(const Eigen::RowVector3d& v) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.block<1, 3>(3, 0) = v;
  return T;
}

/// The map about the origin, in normalized coordinates.
Eigen::Matrix4d mapAboutOrigin(const MapPrescription& p, const Eigen::RowVector3d& axis) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  switch (p.kind) {
    case PrescribedMapKind::Rotation:
      // Row vectors: x -> x R^T rotates by +angle about the axis (right-hand rule).
      M.topLeftCorner<3, 3>() = Eigen::AngleAxisd(p.angle, axis.transpose()).toRotationMatrix().transpose();
      break;
    case PrescribedMapKind::PerspectiveWarp:
      // Weight 1 + strength (x . axis): the far side of a box shrinks, the near side grows.
      M.block<3, 1>(0, 3) = p.strength * axis.transpose();
      break;
    case PrescribedMapKind::UniformScale:
      M.topLeftCorner<3, 3>() *= p.scale;
      break;
  }
  return M;
}

}  // namespace

std::vector<Eigen::Matrix4d> prescribedTargets(const ShapeSpace& space, const MapPrescription& prescription,
                                               const std::vector<Index>& faces) {
  const double axisNorm = prescription.axis.norm();
  if (!(axisNorm > 0.0) || !std::isfinite(axisNorm)) throwUsage("map prescription: the axis must be a nonzero vector");
  if (!std::isfinite(prescription.angle) || !std::isfinite(prescription.strength) ||
      !std::isfinite(prescription.scale) || !prescription.point.allFinite()) {
    throwUsage("map prescription: angle, strength, scale and point must be finite");
  }
  const Eigen::RowVector3d axis = prescription.axis.transpose() / axisNorm;
  const Eigen::Matrix4d aboutOrigin = mapAboutOrigin(prescription, axis);
  auto about = [&](const Eigen::RowVector3d& centre) {
    Eigen::Matrix4d T = translation(-centre) * aboutOrigin * translation(centre);
    return Eigen::Matrix4d(T / T(3, 3));
  };

  std::vector<char> selected(space.faceCount(), faces.empty() ? 1 : 0);
  for (Index f : faces) {
    if (f < 0 || f >= space.faceCount()) {
      throwUsage("map prescription: face " + std::to_string(f) + " is out of range (" +
                 std::to_string(space.faceCount()) + " faces)");
    }
    selected[f] = 1;
  }
  const Eigen::Matrix4d shared =
      prescription.pivot == Pivot::MeshCentre
          ? about(Eigen::RowVector3d::Zero())
          : about(space.normalization().toNormalized(Eigen::RowVector3d(prescription.point.transpose())));
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  for (Index f = 0; f < space.faceCount(); ++f) {
    if (!selected[f]) continue;
    if (prescription.pivot != Pivot::FaceCentroid) {
      targets[f] = shared;
      continue;
    }
    Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
    for (Index v : space.faces()[f]) centroid += space.basePositions().row(v);
    targets[f] = about(centroid / static_cast<double>(space.faces().degree(f)));
  }
  return targets;
}

PrescriptionResult prescribeMaps(compute::Backend& backend, const PolygonMesh& base,
                                 const MapPrescription& prescription, const std::vector<Index>& faces,
                                 const PositionalConstraints& constraints, const PrescriptionSettings& settings) {
  const ShapeSpace space(base);
  GlobalStep global(backend, space, constrainedVertices(constraints), settings.global);
  PrescriptionResult result;
  result.info = global.solve(prescribedTargets(space, prescription, faces), constrainedPositions(base, constraints),
                             result.maps);
  result.mesh.faces = base.faces;
  result.mesh.vertices = space.positions(result.maps.maps);
  result.maxPlanarity = planarityStats(result.mesh).max;
  const double bound = std::max(settings.planarityTolerance, planarityStats(base).max);
  for (int k = 0; k < settings.maxProjectionIterations && result.maxPlanarity > bound; ++k) {
    const LocalStepResult fit = fitFaceMaps(backend, space, result.mesh.vertices);
    result.projection.push_back(global.solve(fit.fits.maps, constrainedPositions(base, constraints), result.maps));
    result.mesh.vertices = space.positions(result.maps.maps);
    result.maxPlanarity = planarityStats(result.mesh).max;
  }
  return result;
}

}  // namespace plano::projective
