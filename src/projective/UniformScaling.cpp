#include "projective/UniformScaling.h"

#include "core/Error.h"

namespace plano::projective {

UniformScalingFamily::UniformScalingFamily(compute::Backend& backend, const PolygonMesh& base, Pivot pivot,
                                           const std::vector<Index>& faces, const PositionalConstraints& constraints,
                                           double t1, double t2, const GlobalStepSettings& settings)
    : space_(base), t1_(t1), t2_(t2) {
  if (!(t1 != t2) || !std::isfinite(t1) || !std::isfinite(t2)) {
    throwUsage("uniform scaling: the two solves need distinct finite scalings");
  }
  // Interpolating the maps is exact only for the unrelaxed projection.
  GlobalStepSettings exact = settings;
  exact.epsilonStart = EpsilonStart::ExactFirst;
  exact.maxEpsilonIncreases = 0;
  GlobalStep global(backend, space_, constrainedVertices(constraints), exact);
  const Positions at = constrainedPositions(base, constraints);
  MapPrescription prescription;
  prescription.kind = PrescribedMapKind::UniformScale;
  prescription.pivot = pivot;
  prescription.scale = t1;
  info1_ = global.solve(prescribedTargets(space_, prescription, faces), at, first_);
  prescription.scale = t2;
  info2_ = global.solve(prescribedTargets(space_, prescription, faces), at, second_);
  if (info1_.epsilon != 0.0 || info2_.epsilon != 0.0) {
    throwNumerical("uniform scaling: no exactly compatible projection of the scalings (the handles are not "
                   "reachable by compatible affine maps); linear interpolation would not stay compatible");
  }
}

std::vector<Eigen::Matrix4d> UniformScalingFamily::maps(double t) const {
  const double w = (t - t1_) / (t2_ - t1_);
  std::vector<Eigen::Matrix4d> result(first_.maps.size());
  for (std::size_t f = 0; f < result.size(); ++f) result[f] = (1.0 - w) * first_.maps[f] + w * second_.maps[f];
  return result;
}

PolygonMesh UniformScalingFamily::mesh(double t) const {
  PolygonMesh out;
  out.faces = space_.faces();
  out.vertices = space_.positions(maps(t));
  return out;
}

}  // namespace plano::projective
