#include "projective/IdealMaps.h"

#include <string>

#include "core/Error.h"
#include "projective/LocalStep.h"

namespace plano::projective {
namespace {

[[noreturn]] void throwCentroidAtInfinity(Index face) {
  throwNumerical("closest ideal map: the fitted map of face " + std::to_string(face) +
                 " sends the face centroid to infinity");
}

/// The maps of a batched ideal-map call, after counting the corner fallbacks and refusing a
/// face whose centroid the fit sends to infinity (no ideal map then).
std::vector<Eigen::Matrix4d> checkedMaps(compute::IdealMaps ideal, Index* fallbacks) {
  const auto faceCount = static_cast<Index>(ideal.maps.size());
  if (fallbacks) *fallbacks = 0;
  for (Index f = 0; f < faceCount; ++f) {
    switch (ideal.methods[f]) {
      case compute::IdealMapMethod::Jacobian: break;
      case compute::IdealMapMethod::CornerProcrustes:
        if (fallbacks) ++*fallbacks;
        break;
      case compute::IdealMapMethod::CentroidAtInfinity: throwCentroidAtInfinity(f);
    }
  }
  return std::move(ideal.maps);
}

}  // namespace

std::vector<Eigen::Matrix4d> closestIdealMaps(compute::Backend& backend, const ShapeSpace& space,
                                              const std::vector<Eigen::Matrix4d>& fitted, IdealMapKind kind,
                                              const Positions* target, Index* fallbacks) {
  const Index faceCount = space.faceCount();
  if (static_cast<Index>(fitted.size()) != faceCount) {
    throwUsage("closest ideal maps: " + std::to_string(fitted.size()) + " maps given for " +
               std::to_string(faceCount) + " faces");
  }
  if (target && target->rows() != space.vertexCount()) {
    throwUsage("closest ideal maps: target has " + std::to_string(target->rows()) + " vertices, the mesh " +
               std::to_string(space.vertexCount()));
  }
  compute::IdealMaps ideal;
  backend.closestIdealMaps(space.faces(), space.basePositions(), fitted, target, kind == IdealMapKind::Similar,
                           ideal);
  return checkedMaps(std::move(ideal), fallbacks);
}

std::vector<Eigen::Matrix4d> fittedIdealMaps(compute::Backend& backend, const ShapeSpace& space,
                                             const Positions& target, IdealMapKind kind, Index* fallbacks) {
  const Positions normalizedTarget = normalizedTargetPositions(space, target);
  compute::IdealMaps ideal;
  backend.fitIdealMaps(space.faces(), space.basePositions(), normalizedTarget, kind == IdealMapKind::Similar, ideal);
  return checkedMaps(std::move(ideal), fallbacks);
}

compute::DeviceMatrix fittedIdealMapsOnDevice(compute::Backend& backend, const ShapeSpace& space,
                                              const Positions& target, IdealMapKind kind, Index* fallbacks) {
  return idealMapsOfNormalized(backend, space, normalizedTargetPositions(space, target), kind, fallbacks);
}

compute::DeviceMatrix idealMapsOfNormalized(compute::Backend& backend, const ShapeSpace& space,
                                            const compute::DeviceMatrix& normalizedTarget, IdealMapKind kind,
                                            Index* fallbacks) {
  if (normalizedTarget.rows() != space.vertexCount() || normalizedTarget.cols() != 3) {
    throwUsage("ideal maps: " + std::to_string(normalizedTarget.rows()) + " x " +
               std::to_string(normalizedTarget.cols()) + " target positions for " +
               std::to_string(space.vertexCount()) + " vertices");
  }
  compute::DeviceIdealMaps ideal;
  backend.fitIdealMapsOnDevice(space.faces(), space.basePositions(), normalizedTarget,
                               kind == IdealMapKind::Similar, ideal);
  if (ideal.centroidsAtInfinity > 0) throwCentroidAtInfinity(ideal.firstCentroidAtInfinity);
  if (fallbacks) *fallbacks = ideal.cornerProcrustes;
  return std::move(ideal.linearColumns);
}

}  // namespace plano::projective
