#pragma once
// Planarization by plain local/global projection (ShapeUp: Bouaziz et al., SGP 2012), the
// method of libigl, libhedra and ShapeOp, kept as the reference the faster methods are
// measured against (issue 9's baseline table; projective-maps paper, Fig. 2 baseline).
//
// Each iteration projects the corners of every face onto its least-squares plane (local)
// and solves a prefactored least-squares system for the positions (global), see
// ShapeUpStep.h for the energy. Converges linearly and slowly: hundreds of iterations
// to 0.1 % on real meshes.
#include <memory>

#include "compute/Backend.h"
#include "planarize/PlanarizeTypes.h"

namespace plano::planarize {
namespace detail {
struct Problem;
class ShapeUpStep;
}  // namespace detail

class ShapeUpPlanarizer {
 public:
  /// Precompute: check and normalize the input (#V x 3), assemble and factor the global
  /// matrix through backend.createSpdSolver. `faces` and `backend` must outlive this object.
  ShapeUpPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                    compute::Backend& backend);
  ~ShapeUpPlanarizer();

  /// Iterate from `vertices` (#V x 3, in: start, usually the input; out: result) until the
  /// max planarity is within settings.tolerance or the iteration cap. Fixed vertices are
  /// reset to their input positions.
  Info solve(Positions& vertices);

 private:
  Settings settings_;
  compute::Backend* backend_;
  std::unique_ptr<detail::Problem> problem_;
  std::unique_ptr<detail::ShapeUpStep> step_;
  double precomputeSeconds_ = 0.0;
};

}  // namespace plano::planarize
