#pragma once
// Non-planar inputs for the planarization tests.
#include "mesh/PolygonMesh.h"

namespace plano::test {

/// A 6 x 6 grid on z = 0.6 x y over [0, 1.2]^2 whose first row is split into triangles and
/// whose second row is merged pairwise into hexagons; the other rows are quads. Open.
PolygonMesh mixedDegreeHyparPatch();

/// Max planarity of the faces at `vertices`, measured independently of a solver's own
/// bookkeeping.
double maxPlanarity(const FaceList& faces, const Positions& vertices);

}  // namespace plano::test
