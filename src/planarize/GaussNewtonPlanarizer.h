#pragma once
// Planarization by Gauss-Newton steps on the planarity measure itself: one constraint per
// run of four consecutive corners (one per quad, k per k-gon, none for triangles),
//   c_j(x) = (b - a).((c - a) x (d - b)) / (|(c - a) x (d - b)| L_j),
// the signed distance between the diagonals ac and bd over their mean length L_j: exactly
// the papers' planarity (mesh/Planarity.h) with a sign. Each iteration linearizes c at x^k
// (exact gradient) and takes the step
//   min_dx |dx - dx0|^2  subject to  J dx + c = 0  (softened by a tiny nu),
//   dx0 = w / (w + mu) (x^input - x^k)  (w closeness, mu damping: a pull back to the input),
// over the free vertices, whose solution is
//   dx = dx0 - J^T y,   (J J^T + nu I) y = c + J dx0:
// a scalar SPD system with one unknown per constraint row and the sparsity of "rows that
// share a vertex": for quad meshes #F unknowns and about 9 entries per row, the size and
// fill of ShapeUp's matrix, instead of the 3 #V unknowns with 3x3 blocks of the primal
// normal equations (GuidedProjectionPlanarizer). After the step, up to
// settings.correctorSteps chord steps dx = -J^T (J J^T + nu I)^-1 c(x) reuse the same
// factorization on the new residuals (Newton's method for the projection with a frozen
// Jacobian), each one back-substitution. Safeguard: backtracking on the merit sum c_j^2;
// when no step length decreases it, the iteration is retried without the pull back to the
// input (a descent direction) and with more softening.
//
// Why this method (measured, bench/PlanarizeBench.cpp): on the five meshes it
// reaches 0.1 % in 2-10 iterations (plus a few corrector back-substitutions) where ShapeUp
// needs hundreds to over a thousand and Anderson-accelerated ShapeUp tens to hundreds, and
// each iteration costs one scalar sparse factorization of ShapeUp's size. Planarity is a
// constraint, not a penalty, so the closeness weight does not limit the planarity reached;
// the step is the smallest correction of the linearized faces, which keeps the mesh close
// to the input (max displacement 1.4 % of the bounding-box diagonal on spot_quad, against
// the baseline's 4-6 %). Known limit: the factorization is O(n^1.5) on surface meshes, so
// the per-iteration cost grows faster than linearly (see the benchmark's slope).
// This is Goldenthal et al.'s fast projection (SCA 2007) applied to planarity.
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
