#include "planarize/PlanarizeTestMeshes.h"

#include "mesh/Planarity.h"

namespace plano::test {

PolygonMesh mixedDegreeHyparPatch() {
  constexpr Index n = 6;
  PolygonMesh mesh;
  mesh.vertices.resize((n + 1) * (n + 1), 3);
  auto id = [](Index i, Index j) { return j * (n + 1) + i; };
  for (Index j = 0; j <= n; ++j) {
    for (Index i = 0; i <= n; ++i) {
      const double x = 0.2 * i, y = 0.2 * j;
      mesh.vertices.row(id(i, j)) << x, y, 0.6 * (x - 0.6) * (y - 0.6);
    }
  }
  for (Index i = 0; i < n; ++i) {
    mesh.faces.addFace({id(i, 0), id(i + 1, 0), id(i + 1, 1)});
    mesh.faces.addFace({id(i, 0), id(i + 1, 1), id(i, 1)});
  }
  for (Index i = 0; i < n; i += 2) {
    mesh.faces.addFace({id(i, 1), id(i + 1, 1), id(i + 2, 1), id(i + 2, 2), id(i + 1, 2), id(i, 2)});
  }
  for (Index j = 2; j < n; ++j) {
    for (Index i = 0; i < n; ++i) mesh.faces.addFace({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  }
  return mesh;
}

double maxPlanarity(const FaceList& faces, const Positions& vertices) {
  return planarityStats(PolygonMesh{vertices, faces}).max;
}

}  // namespace plano::test
