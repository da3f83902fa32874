#pragma once
// Batched local step of the projective-maps paper (§4.1, Eq. 3): the best projective map
// of every face from the base mesh of a shape space to target positions, with the induced
// scale factors. Runs through Backend::fitProjectiveMaps (CPU reference or GPU kernel).
#include <vector>

#include "compute/Backend.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

struct LocalStepResult {
  FaceMaps fits;                ///< Fitted maps T_f (normalized coordinates) and their shat_{f,i}.
  std::vector<double> residuals;  ///< Per face: RMS residual of Eq. 3 (0 for an exact fit).
  Index nonPositiveScales = 0;  ///< Corners with shat <= 0 (mapped through the plane at infinity).
  double maxResidual = 0.0;
};

/// `target` (#V x 3, world coordinates) in the space's normalized coordinates, after the
/// checks of fitFaceMaps (Error(BadInput) for the wrong size or a non-finite entry).
Positions normalizedTargetPositions(const ShapeSpace& space, const Positions& target);

/// Fit T_f for every face: (p_i, 1) T_f = shat_{f,i} (q_i, 1), the face's mean shat 1, both corner
/// sets first projected onto their best-fitting planes (§5 step 1); the solution closest
/// to the identity when not unique, least squares when over-determined.
///   backend  in: where the batched fit runs.
///   space    in: base mesh p_i (normalized internally).
///   target   in: #V x 3 target positions q_i in world coordinates.
/// Throws Error(BadInput) if target has the wrong size or non-finite entries.
LocalStepResult fitFaceMaps(compute::Backend& backend, const ShapeSpace& space, const Positions& target);

}  // namespace plano::projective
