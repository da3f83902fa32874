#pragma once
// Positional constraints inside a linear space (linear-spaces paper, Fig. 4 and §3
// "Handle-based deformation"): the members N W whose constrained vertices sit at their
// targets, as far as the space allows. W = particular + free * V, where `particular` is
// the minimum-norm least-squares solution of (C N) W = c and `free` an orthonormal basis
// of null(C N): every V keeps the constraint residual at its least possible value.
#include "mesh/Constraints.h"
#include "subspace/SubspaceBasis.h"

namespace plano::subspace {

struct ConstrainedSubspace {
  Eigen::VectorXd particular;   ///< d coefficients.
  Eigen::MatrixXd free;         ///< d x d' orthonormal columns.
  double constraintResidual = 0.0;  ///< ||C N particular - c||: 0 when the space can meet the constraints.
  Index constraintRank = 0;         ///< rank(C N).
};

/// Constrain the space: fixed vertices stay at their `rest` position, handles go to
/// theirs. `rankTolerance` is relative to the largest pivot of (C N)^T. Throws
/// Error(BadInput) naming the vertex for an index out of range.
ConstrainedSubspace constrainSubspace(const SubspaceBasis& N, const PositionalConstraints& constraints,
                                      const Positions& rest, double rankTolerance = 1e-9);

/// Closest member to `target` under the constraints (Fig. 4): min ||N W - target|| over
/// W = particular + free V. Also the orthogonal projection when there are no constraints.
Positions closestInSubspace(const SubspaceBasis& N, const ConstrainedSubspace& constrained, const Positions& target);

}  // namespace plano::subspace
