#pragma once
// Closest ideal maps of the projective-maps paper (App. A): the rigid or similarity map
// closest to a fitted projective face map, the targets of as-rigid / as-similar-as-possible
// deformation (§6.1).
#include <Eigen/Core>
#include <vector>

#include "compute/Backend.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

enum class IdealMapKind {
  Rigid,    ///< Rotation + translation (orthogonal Procrustes).
  Similar,  ///< Uniform scale * rotation + translation.
};

/// For every face f, the ideal map closest to the fitted projective map T_f.
///
/// A projective map is not affine, so it has no single linear part: we take its Jacobian
/// J at the centroid c of the (plane-projected) source face, restricted to the face plane
/// (the fit leaves the out-of-plane action arbitrary, "closest to the identity", which must
/// not leak into the rotation). The 3x3 linear map L sends the source plane basis e1, e2
/// to e1 J, e2 J and the source normal to the unit normal of their span, so L maps plane
/// to plane and normal to normal and its closest rotation R is
/// the in-plane rotation of the fit. The similarity scale is the mean of the two
/// singular values of the in-plane 2x2 map, s = (s1 + s2) / 2 = sqrt(|M|^2 + 2|det M|) / 2.
/// The translation keeps the first-order expansion of the fit about the centroid:
/// x -> phi(c) + (x - c) s R, with phi the dehomogenized fitted map.
///
///   backend  in: runs the batched maps (Backend::closestIdealMaps; the per-face math is
///            projective/IdealMapFit.h's, a kernel of its own on Vulkan).
///   space    in: base mesh (normalized coordinates).
///   fitted   in: #F fitted maps T_f (normalized coordinates, row-vector convention).
///   kind     in: rigid or similar.
///   target   in (optional): #V x 3 normalized target positions the maps were fitted to.
///            A least-squares fit of a non-planar face with more than four corners can
///            send part of the face through the plane at infinity (corner or centroid
///            weights of mixed sign); such a fit has no meaningful Jacobian, and with
///            `target` the face falls back to the classical corner-set Procrustes
///            (Kabsch; Umeyama's scale for similarities) between its source and target
///            corners. `fallbacks` (optional) receives the number of such faces.
/// Returns #F affine maps [[s R, 0], [t, 1]] (row-vector convention, A(3, 3) = 1).
/// Throws Error(Numerical) naming the face when a fit is degenerate and no target is given.
std::vector<Eigen::Matrix4d> closestIdealMaps(compute::Backend& backend, const ShapeSpace& space,
                                              const std::vector<Eigen::Matrix4d>& fitted, IdealMapKind kind,
                                              const Positions* target = nullptr, Index* fallbacks = nullptr);

/// The local step of rigid or similar deformation (§6.1) in one backend call
/// (Backend::fitIdealMaps): the projective fit of every face from the base mesh to
/// `target` (#V x 3, world coordinates; fitFaceMaps's checks), then its closest ideal map
/// as closestIdealMaps with the normalized target as the corner fallback's positions. The
/// fits are not returned, so a device backend keeps them on the device.
std::vector<Eigen::Matrix4d> fittedIdealMaps(compute::Backend& backend, const ShapeSpace& space,
                                             const Positions& target, IdealMapKind kind, Index* fallbacks = nullptr);

/// fittedIdealMaps with the maps left where the backend computed them
/// (Backend::fitIdealMapsOnDevice): their first three columns, 4 #F x 3 (GlobalStep::
/// solveAffine's targets; fourth columns (0, 0, 0, 1)). The same checks and errors.
compute::DeviceMatrix fittedIdealMapsOnDevice(compute::Backend& backend, const ShapeSpace& space,
                                              const Positions& target, IdealMapKind kind, Index* fallbacks = nullptr);
/// The same for target positions already in normalized coordinates (#V x 3), which may be a
/// device matrix of the backend's (Backend::mapPositions): bound where they are.
compute::DeviceMatrix idealMapsOfNormalized(compute::Backend& backend, const ShapeSpace& space,
                                            const compute::DeviceMatrix& normalizedTarget, IdealMapKind kind,
                                            Index* fallbacks = nullptr);

}  // namespace plano::projective
