#include "projective/LocalStep.h"

#include <algorithm>
#include <string>

#include "core/Error.h"

namespace plano::projective {

Positions normalizedTargetPositions(const ShapeSpace& space, const Positions& target) {
  if (target.rows() != space.vertexCount()) {
    throwBadInput("local step: target has " + std::to_string(target.rows()) + " vertices, the base mesh " +
                  std::to_string(space.vertexCount()));
  }
  for (Index v = 0; v < space.vertexCount(); ++v) {
    if (!target.row(v).allFinite()) {
      throwBadInput("local step: target vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  return space.normalization().toNormalized(target);
}

LocalStepResult fitFaceMaps(compute::Backend& backend, const ShapeSpace& space, const Positions& target) {
  const Positions normalizedTarget = normalizedTargetPositions(space, target);
  compute::ProjectiveFits fits;
  backend.fitProjectiveMaps(space.faces(), space.basePositions(), normalizedTarget, fits);

  LocalStepResult result;
  result.fits.maps = std::move(fits.maps);
  // The backend's reciprocal scales are taken on the plane-projected source corners; the
  // global step uses the base corners themselves, so recompute them there (equal for a
  // planar base mesh).
  result.fits.reciprocalScales = space.inducedReciprocalScales(result.fits.maps);
  result.residuals = std::move(fits.residuals);
  for (double s : result.fits.reciprocalScales) result.nonPositiveScales += s <= 0.0 ? 1 : 0;
  for (double r : result.residuals) result.maxResidual = std::max(result.maxResidual, r);
  return result;
}

}  // namespace plano::projective
