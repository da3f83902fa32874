#pragma once
// Planarization by ShapeUp's local/global fixed point with Anderson acceleration (Peng,
// Deng, Zhang, Zhang, "Anderson Acceleration for Geometry Optimization and Physics
// Simulation", SIGGRAPH 2018): each iteration extrapolates from the last m iterates of the
// map G = global o local, and a safeguard falls back to the plain step G(u) whenever the
// accelerated iterate has a higher ShapeUp energy than the previous one, so the energy
// never rises. Same per-iteration cost as ShapeUp (one local step, one prefactored
// back-substitution, an m x m least-squares problem), far fewer iterations.
#include <memory>

#include "compute/Backend.h"
#include "planarize/PlanarizeTypes.h"

namespace plano::planarize {
namespace detail {
struct Problem;
class ShapeUpStep;
}  // namespace detail

class AndersonPlanarizer {
 public:
  /// Precompute as ShapeUpPlanarizer (same energy, same factored matrix).
  AndersonPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                     compute::Backend& backend);
  ~AndersonPlanarizer();

  /// Iterate from `vertices` (#V x 3, in: start; out: result); see ShapeUpPlanarizer::solve.
  /// Info::rejectedSteps counts the safeguard's fallbacks.
  Info solve(Positions& vertices);

 private:
  Settings settings_;
  compute::Backend* backend_;
  std::unique_ptr<detail::Problem> problem_;
  std::unique_ptr<detail::ShapeUpStep> step_;
  double precomputeSeconds_ = 0.0;
};

}  // namespace plano::planarize
