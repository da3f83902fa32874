#include "planarize/AndersonPlanarizer.h"

#include <Eigen/Dense>

#include "core/Timing.h"
#include "planarize/Monitor.h"
#include "planarize/Problem.h"
#include "planarize/ShapeUpStep.h"

namespace plano::planarize {
namespace {
using FlatView = Eigen::Map<Eigen::VectorXd>;
using ConstFlatView = Eigen::Map<const Eigen::VectorXd>;
}  // namespace

AndersonPlanarizer::AndersonPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                                       compute::Backend& backend)
    : settings_(settings), backend_(&backend) {
  const auto start = SteadyClock::now();
  problem_ = std::make_unique<detail::Problem>(detail::makeProblem(faces, input, settings));
  step_ = std::make_unique<detail::ShapeUpStep>(*problem_, settings.closeness, backend);
  precomputeSeconds_ = secondsSince(start);
}

AndersonPlanarizer::~AndersonPlanarizer() = default;

Info AndersonPlanarizer::solve(Positions& vertices) {
  const auto start = SteadyClock::now();
  const detail::Problem& problem = *problem_;
  Positions Y = detail::startingPoint(problem, vertices);
  Info info;
  detail::Monitor monitor(problem, *backend_, settings_.tolerance);
  bool converged = monitor.record(Y, info);

  const Eigen::Index n = Y.size();
  const int depth = settings_.andersonDepth;
  // Differences of the residuals f = G(u) - u and of the images G(u) between consecutive
  // iterates, in a ring buffer of `depth` columns. Fixed vertices have zero rows.
  Eigen::MatrixXd dF(n, depth), dG(n, depth);
  Eigen::VectorXd previousF(n), previousG(n), f(n);
  int stored = 0;
  int slot = 0;

  double energy = step_->project(Y);
  Positions G = Y;
  if (!converged && settings_.maxIterations > 0) step_->globalStep(G);
  Positions candidate;
  while (!converged && info.iterations < settings_.maxIterations) {
    const ConstFlatView y(Y.data(), n), g(G.data(), n);
    f = g - y;
    if (info.iterations > 0) {
      dF.col(slot) = f - previousF;
      dG.col(slot) = g - previousG;
      slot = (slot + 1) % depth;
      stored = std::min(stored + 1, depth);
    }
    previousF = f;
    previousG = g;
    if (f.cwiseAbs().maxCoeff() < 1e-12) {
      info.status = Status::Stalled;
      break;
    }
    candidate = G;
    if (stored > 0) {
      // theta = argmin |f - dF theta|: m x m normal equations, m <= depth; the tiny
      // Tikhonov term keeps them solvable when the history is (nearly) dependent.
      const auto F = dF.leftCols(stored);
      Eigen::MatrixXd normal = F.transpose() * F;
      normal.diagonal().array() += 1e-10 * normal.diagonal().maxCoeff() + 1e-300;
      const Eigen::VectorXd theta = normal.ldlt().solve(F.transpose() * f);
      FlatView(candidate.data(), n) -= dG.leftCols(stored) * theta;
    }
    double candidateEnergy = step_->project(candidate);
    // Safeguard: the plain step G never raises the energy; an extrapolated one might.
    if (stored > 0 && !(candidateEnergy < energy)) {
      ++info.rejectedSteps;
      candidate = G;
      candidateEnergy = step_->project(candidate);
    }
    Y.swap(candidate);
    energy = candidateEnergy;
    ++info.iterations;
    converged = monitor.record(Y, info);
    if (!converged && info.iterations < settings_.maxIterations) {
      G = Y;
      step_->globalStep(G);
      info.linearResidual = std::max(info.linearResidual, step_->linearResidual());
    }
  }
  detail::finishSolve(problem, Y, converged, precomputeSeconds_ + secondsSince(start), info, vertices);
  return info;
}

}  // namespace plano::planarize
