#include "planarize/ShapeUpPlanarizer.h"

#include "core/Timing.h"
#include "planarize/Monitor.h"
#include "planarize/Problem.h"
#include "planarize/ShapeUpStep.h"

namespace plano::planarize {

ShapeUpPlanarizer::ShapeUpPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                                     compute::Backend& backend)
    : settings_(settings), backend_(&backend) {
  const auto start = SteadyClock::now();
  problem_ = std::make_unique<detail::Problem>(detail::makeProblem(faces, input, settings));
  step_ = std::make_unique<detail::ShapeUpStep>(*problem_, settings.closeness, backend);
  precomputeSeconds_ = secondsSince(start);
}

ShapeUpPlanarizer::~ShapeUpPlanarizer() = default;

Info ShapeUpPlanarizer::solve(Positions& vertices) {
  const auto start = SteadyClock::now();
  const detail::Problem& problem = *problem_;
  Positions Y = detail::startingPoint(problem, vertices);
  Info info;
  detail::Monitor monitor(problem, *backend_, settings_.tolerance);
  bool converged = monitor.record(Y, info);
  Positions previous;
  while (!converged && info.iterations < settings_.maxIterations) {
    previous = Y;
    step_->project(Y);
    step_->globalStep(Y);
    ++info.iterations;
    info.linearResidual = std::max(info.linearResidual, step_->linearResidual());
    converged = monitor.record(Y, info);
    // Stalled: the fixed point of the closeness-weighted energy is above the tolerance.
    if (!converged && (Y - previous).cwiseAbs().maxCoeff() < 1e-12) {
      info.status = Status::Stalled;
      break;
    }
  }
  detail::finishSolve(problem, Y, converged, precomputeSeconds_ + secondsSince(start), info, vertices);
  return info;
}

}  // namespace plano::planarize
