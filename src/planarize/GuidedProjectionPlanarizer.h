#pragma once
// Planarization by Gauss-Newton steps on per-face plane constraints, in the manner of
// guided projection (Tang, Sun, Gomes, Wallner, Pottmann, "Form-finding with polyhedral
// meshes made simple", SIGGRAPH 2014), with the plane unknowns eliminated per face.
//
// Unknowns: free vertex positions x_i and, per face f of degree >= 4, a plane (n_f, d_f).
// Each iteration minimizes, around the current iterate (x^k, n^k, d^k),
//   sum_f 1/h_f^2 sum_{i in f} (n^k.x_i + n_f.x_i^k - n^k.x_i^k - d_f)^2   (linearized n_f.x_i = d_f)
//   + sum_f (n^k.n_f - (|n^k|^2 + 1)/2)^2                                 (linearized |n_f| = 1)
//   + w sum_i |x_i - x_i^input|^2                                          (closeness)
//   + eps (|x - x^k|^2 + |n - n^k|^2 + |d - d^k|^2)                        (Levenberg-Marquardt)
// h_f is the face's mean diagonal, so the residual is the planarity measure's numerator
// over its denominator. The 4x4 plane block of each face is eliminated (Schur complement),
// leaving an SPD system in the 3 #free vertex coordinates whose face blocks are
// K_ij n n^T: the sparsity of the mesh's face adjacency, fixed across iterations. A step
// that raises the penalty energy (corner-to-best-plane distances + closeness) is
// rejected and retried with ten times the damping.
//
// Kept as a comparison for GaussNewtonPlanarizer (bench/PlanarizeBench.cpp): its closeness
// is a penalty, so its fixed point stays slightly non-planar and the last tenth of a
// percent takes many iterations; and its reduced system has 3 #free unknowns with 3x3
// blocks, about 27 times the factorization flops of a scalar system on the same mesh.
#include <memory>

#include "compute/Backend.h"
#include "planarize/PlanarizeTypes.h"

namespace plano::planarize {
namespace detail {
struct Problem;
struct GuidedProjectionWorkspace;
}  // namespace detail

class GuidedProjectionPlanarizer {
 public:
  /// Precompute: check and normalize the input (#V x 3), build the sparsity pattern of the
  /// reduced system and the per-face slots into it. `faces` and `backend` must outlive
  /// this object.
  GuidedProjectionPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                        compute::Backend& backend);
  ~GuidedProjectionPlanarizer();

  /// Iterate from `vertices` (#V x 3, in: start, usually the input; out: result) until the
  /// max planarity is within settings.tolerance or the iteration cap (one iteration = one
  /// linear solve, rejected steps included). Fixed vertices keep their input positions.
  Info solve(Positions& vertices);

 private:
  Settings settings_;
  compute::Backend* backend_;
  std::unique_ptr<detail::Problem> problem_;
  std::unique_ptr<detail::GuidedProjectionWorkspace> workspace_;
  double precomputeSeconds_ = 0.0;
};

}  // namespace plano::planarize
