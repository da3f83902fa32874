#pragma once
// One call to planarize a polygon mesh with any of the methods (issue 9, and the
// planarization baseline of the projective-maps paper, §5 / Fig. 2): moves the vertices so
// that every face of degree >= 4 becomes planar within a tolerance of the papers'
// planarity measure, staying close to the input (closeness weight, fixed vertices).
// For repeated solves on one mesh use the method's class directly (precompute once).
#include "compute/Backend.h"
#include "planarize/PlanarizeTypes.h"

namespace plano::planarize {

/// Planarize `vertices` (#V x 3, in: input and closeness target; out: result) of a mesh
/// with `faces`, with settings.method. The status says whether the tolerance was met;
/// throws Error(BadInput) for malformed input, Error(Usage) for bad settings and
/// Error(Numerical) when a solve fails.
Info planarize(const FaceList& faces, Positions& vertices, const Settings& settings, compute::Backend& backend);

}  // namespace plano::planarize
