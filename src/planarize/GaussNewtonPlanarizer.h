#pragma once
// Planarization by Gauss-Newton steps on the planarity measure itself: one constraint per
// run of four consecutive corners (one per quad, k per k-gon, none for triangles),
//   c_j(x) = (b - a).((c - a) x (d - b)) / (|(c - a) x (d - b)| L_j),
// the signed distance between the diagonals ac and bd over their mean length L_j: exactly
// the papers' planarity (mesh/Planarity.h) with a sign. Each iteration linearizes c at x^k
// (the normalizing factor |m| L frozen, so the row is grad V / (|m| L)) and takes the step
//   min_dx |J dx + c|^2 + mu |dx|^2 + w |x^k + dx - x^input|^2
// over the free vertices. With nu = mu + w and dx0 = (w / nu)(x^input - x^k), its solution is
//   dx = dx0 - J^T y,   (J J^T + nu I) y = c + J dx0,
// a scalar SPD system with one unknown per constraint row and the sparsity of "rows that
// share a vertex": for quad meshes about #F unknowns and 9 entries per row, the size and
// fill of ShapeUp's matrix, instead of the 3 #V unknowns with 3x3 blocks of the primal
// normal equations (GuidedProjectionPlanarizer). Levenberg-Marquardt safeguard: a step
// that raises the merit sum c_j^2 + w |x - x^input|^2 is retried with ten times mu.
//
// Why this method (measured, bench/PlanarizeBench.cpp): Gauss-Newton needs a handful of
// iterations where ShapeUp needs hundreds and Anderson-accelerated ShapeUp tens to hundreds,
// and with the constraint-space ("dual") system each iteration costs one scalar sparse
// factorization of the size of ShapeUp's prefactored matrix. The step is the smallest
// displacement that makes the linearized faces planar, which keeps the mesh close to the
// input. It is Goldenthal et al.'s fast projection (SCA 2007) applied to planarity.
#include <memory>

#include "compute/Backend.h"
#include "planarize/PlanarizeTypes.h"

namespace plano::planarize {
namespace detail {
struct Problem;
struct GaussNewtonWorkspace;
}  // namespace detail

class GaussNewtonPlanarizer {
 public:
  /// Precompute: check and normalize the input (#V x 3), list the constraint rows, build the
  /// sparsity pattern of J J^T and the slots each vertex writes into. `faces` and `backend`
  /// must outlive this object.
  GaussNewtonPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                        compute::Backend& backend);
  ~GaussNewtonPlanarizer();

  /// Iterate from `vertices` (#V x 3, in: start, usually the input; out: result) until the
  /// max planarity is within settings.tolerance or the iteration cap (one iteration = one
  /// linear solve, rejected steps included). Fixed vertices keep their input positions.
  Info solve(Positions& vertices);

 private:
  Settings settings_;
  compute::Backend* backend_;
  std::unique_ptr<detail::Problem> problem_;
  std::unique_ptr<detail::GaussNewtonWorkspace> workspace_;
  double precomputeSeconds_ = 0.0;
};

}  // namespace plano::planarize
