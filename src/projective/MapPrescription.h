#pragma once
// Editing by direct map prescription (projective-maps paper, §7): prescribe simple maps
// (rotations, perspective warps that turn boxes into frusta, uniform scalings) to all or
// selected faces, keep some positions fixed, and project with the global step (Eq. 4).
#include <Eigen/Core>
#include <vector>

#include "compute/Backend.h"
#include "mesh/Constraints.h"
#include "projective/ConstrainedVertices.h"
#include "projective/GlobalStep.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

enum class PrescribedMapKind {
  Rotation,         ///< x -> (x - c) R + c, R = rotation by `angle` about `axis`.
  PerspectiveWarp,  ///< x -> c + (x - c) / (1 + strength (x - c).axis / diagonal): boxes to frusta.
  UniformScale,     ///< x -> c + t (x - c); about the mesh centre this is diag(t, t, t, 1) of §7.
};

/// Where the centre c of a prescribed map lies.
enum class Pivot {
  MeshCentre,    ///< Bounding-box centre of the base mesh (the normalized origin).
  FaceCentroid,  ///< Each face's own corner centroid: every face turns/warps/scales in place.
  Point,         ///< `point`, world coordinates.
};

struct MapPrescription {
  PrescribedMapKind kind = PrescribedMapKind::Rotation;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< Rotation axis or warp direction (normalized internally).
  double angle = 0.0;     ///< Radians (rotation).
  double strength = 0.0;  ///< Warp: relative change of the homogeneous weight per bounding-box diagonal.
  double scale = 1.0;     ///< t of the uniform scaling.
  Pivot pivot = Pivot::MeshCentre;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< Pivot::Point only.
};

/// The prescribed map T_f of every face, in the shape space's normalized coordinates
/// (T(3, 3) = 1). Faces not in `faces` get the identity; an empty `faces` selects all.
/// Throws Error(Usage) for a zero axis or an out-of-range face.
std::vector<Eigen::Matrix4d> prescribedTargets(const ShapeSpace& space, const MapPrescription& prescription,
                                               const std::vector<Index>& faces = {});

struct PrescriptionSettings {
  /// Affine prescriptions (rotations, scalings) induce unit scale factors, so the identity
  /// is always a feasible exact solution: try eps = 0 first.
  GlobalStepSettings global = [] {
    GlobalStepSettings s;
    s.epsilonStart = EpsilonStart::ExactFirst;
    return s;
  }();
  /// Percent. A projective prescription (warp) may need eps > 0; then the §5 loop
  /// (projective fit of the current faces, global step) runs while the max planarity
  /// exceeds this or the base mesh's own, whichever is larger.
  double planarityTolerance = 0.1;
  int maxProjectionIterations = 20;
};

struct PrescriptionResult {
  PolygonMesh mesh;
  FaceMaps maps;
  GlobalStepInfo info;                    ///< The projection of the prescribed maps.
  std::vector<GlobalStepInfo> projection;  ///< The §5 loop's global steps, if it ran.
  double maxPlanarity = 0.0;              ///< Percent, of the result.
};

/// Prescribe and project: a global step of the prescribed targets with the constraints'
/// fixed vertices at their base positions and handles at their positions, then, if the
/// faces are not planar enough, the §5 loop with the same constraints.
///   base         in: polyhedral base mesh (world coordinates).
///   faces        in: faces that get the prescribed map (empty = all), the others the identity.
/// Throws Error(Numerical) as GlobalStep::solve does.
PrescriptionResult prescribeMaps(compute::Backend& backend, const PolygonMesh& base,
                                 const MapPrescription& prescription, const std::vector<Index>& faces,
                                 const PositionalConstraints& constraints, const PrescriptionSettings& settings = {});

}  // namespace plano::projective
