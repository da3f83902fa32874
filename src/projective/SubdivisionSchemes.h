#pragma once
// Target positions of the linear subdivision schemes that PQ subdivision imitates
// (projective-maps paper, §5: "Our model linear subdivisions are the tensor-product
// four-points scheme [Kob96] for interpolatory subdivision, and the Catmull-Clark scheme
// [CC98] for approximate subdivision"). Both produce positions for the fine vertices of
// the trivial quad refinement (QuadRefinement.h layout); the topology is the same.
#include <string>

#include "mesh/PolygonMesh.h"
#include "projective/QuadRefinement.h"

namespace plano::projective {

enum class SubdivisionScheme {
  /// Catmull-Clark (approximating). Face point: centroid. Interior edge point:
  /// (a + b + F1 + F2) / 4. Interior vertex of valence n: (Q + 2R + (n - 3) v) / n with Q the
  /// mean of the adjacent face points and R the mean of the incident edge midpoints.
  /// Boundary: the cubic B-spline curve rules along each boundary curve (edge point =
  /// midpoint, vertex = (a + 6 v + b) / 8 with a, b its boundary neighbours); a corner of
  /// valence 2 (one face) and a vertex on more than two boundary edges stay where they are.
  CatmullClark,
  /// Kobbelt's tensor-product four-point scheme (interpolating): coarse vertices stay.
  /// Edge point of (a, b): (-a' + 9 a + 9 b - b') / 16 with a', b' the continuations of
  /// the grid line beyond a and b:
  ///  - at an interior vertex of valence 4: the opposite neighbour (the regular rule);
  ///  - along a boundary curve (boundary edge, vertex with two boundary edges and >= 2
  ///    faces): the next boundary vertex (the boundary curve gets the 1D four-point rule);
  ///  - at an interior extraordinary vertex v of valence n, for edge (v, w): the ghost
  ///    2 v - w + (2 / n) sum_j (n_j - v), which equals the opposite neighbour on a regular
  ///    grid sampled from a sphere (isotropic curvature) and keeps flat meshes flat;
  ///  - otherwise (an interior edge at a boundary vertex, a corner): the reflected ghost
  ///    2 v - w, which reproduces straight lines.
  /// Face point of a quad: the four-point rule applied across the face to the new edge
  /// points of two opposite edges, continued by the edge points of the opposite edges in
  /// the neighbouring quads (reflected ghost 2 E0 - E2 where there is none), averaged
  /// over the two directions; on a regular grid both directions agree (tensor product).
  /// Face point of a k-gon, k != 4 (no grid lines), Catmull-Clark-like fallback:
  /// 2 mean(edge points) - mean(corners), the face centre displaced twice as far as the
  /// edge midpoints, as on a surface of isotropic curvature.
  FourPoint,
};

/// "catmull-clark" or "four-point"; throws Error(Usage) naming the text otherwise.
SubdivisionScheme parseSubdivisionScheme(const std::string& text);
const char* toString(SubdivisionScheme scheme);

/// True for schemes whose coarse vertices keep their positions on the fine level.
inline bool isInterpolating(SubdivisionScheme scheme) { return scheme == SubdivisionScheme::FourPoint; }

/// Positions of one step of the linear scheme. In: `coarseFaces` and `coarse` (#V x 3),
/// the mesh that `refinement` was built from. Returns #fine V x 3 positions in the layout
/// of QuadRefinement.h. Throws Error(Usage) if the mesh does not match the refinement.
Positions linearSubdivision(SubdivisionScheme scheme, const FaceList& coarseFaces, const Positions& coarse,
                            const QuadRefinement& refinement);

}  // namespace plano::projective
