#include "projective/Normalization.h"

namespace plano::projective {

Normalization Normalization::fromBoundingBox(const Positions& reference) {
  Normalization n;
  if (reference.rows() == 0) return n;
  const Eigen::RowVector3d lo = reference.colwise().minCoeff();
  const Eigen::RowVector3d hi = reference.colwise().maxCoeff();
  n.centre = 0.5 * (lo + hi);
  const double diagonal = (hi - lo).norm();
  n.scale = diagonal > 0.0 && std::isfinite(diagonal) ? diagonal : 1.0;
  return n;
}

Positions Normalization::toNormalized(const Positions& world) const {
  return ((world.rowwise() - centre) / scale).eval();
}

Positions Normalization::toWorld(const Positions& normalized) const {
  return ((normalized * scale).rowwise() + centre).eval();
}

}  // namespace plano::projective
