#pragma once
// Giving a flat polyhedral mesh height with its affine space (linear-spaces paper, §4
// "Design pipeline": "the first step is to afford them some height ... using the affine
// linear subspace"). The z-coordinates of the members of the affine space of a flat mesh
// are its liftings: heights that keep every face planar. The planar liftings (1, x, y)
// are removed; what remains is lifted either by its lowest-frequency eigenshape or by a
// handle (one vertex raised, the boundary held at zero as far as the space allows).
#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

enum class LiftKind { Eigenshape, Handle };

struct LiftSettings {
  LiftKind kind = LiftKind::Eigenshape;
  double height = 0.25;      ///< Largest height, relative to the bounding-box diagonal.
  Index eigenshape = 0;      ///< Which non-planar eigenshape (0 = lowest frequency).
  Index handleVertex = -1;   ///< Handle kind: the raised vertex (-1: the vertex nearest the centroid).
};

struct LiftInfo {
  Index liftings = 0;       ///< Dimension of the non-planar liftings.
  double maxHeight = 0.0;
};

/// Lift a flat mesh lying in the plane z = 0. Throws Error(BadInput) when the mesh is not
/// flat, Error(Numerical) when the topology only admits planar liftings (e.g. 3-regular
/// graphs, Appendix 2), Error(Usage) for an eigenshape index out of range.
/// The eigenshape kind's reduced operator M^T L M runs on `backend` (Backend::reducedOperator);
/// the affine space's basis and the small eigenproblem on the host.
PolygonMesh liftWithAffineSpace(compute::Backend& backend, const PolygonMesh& flat, const LiftSettings& settings = {},
                                LiftInfo* info = nullptr);
/// The same on the CPU reference.
PolygonMesh liftWithAffineSpace(const PolygonMesh& flat, const LiftSettings& settings = {}, LiftInfo* info = nullptr);

}  // namespace plano::subspace
