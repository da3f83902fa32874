#pragma once
// Similarity normalization of coordinates for the projective framework.
//
// "The map closest to the identity" (local step) and A(3, 3) = 1 are not translation or
// scale invariant: a face plane through the origin makes the normalization degenerate.
// Every projective computation therefore runs on coordinates centred at the bounding-box
// centre and scaled to unit bounding-box diagonal; results are mapped back on output.
#include <Eigen/Core>

#include "mesh/PolygonMesh.h"

namespace plano::projective {

/// x_normalized = (x - centre) / scale.
struct Normalization {
  Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
  double scale = 1.0;  ///< Bounding-box diagonal of the reference positions (1 if degenerate).

  /// Centre and diagonal of the bounding box of `reference` (#V x 3). An empty or
  /// single-point reference gives the identity normalization.
  static Normalization fromBoundingBox(const Positions& reference);

  Positions toNormalized(const Positions& world) const;
  Positions toWorld(const Positions& normalized) const;
  Eigen::RowVector3d toNormalized(const Eigen::RowVector3d& world) const { return (world - centre) / scale; }
  Eigen::RowVector3d toWorld(const Eigen::RowVector3d& normalized) const { return normalized * scale + centre; }
};

}  // namespace plano::projective
