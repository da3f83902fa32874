// The device ADMM's polish (AdmmKernels, VulkanAdmm.h): refinements of an active set by the
// method of multipliers on the device, the active sides, and the bound violation.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "compute/vulkan/VulkanAdmm.h"
#include "compute/vulkan/VulkanAdmmWorkspace.h"
#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::vk {

using namespace admm;

void AdmmKernels::recordPolish() {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  Workspace::Polish& p = *w.polish;
  const int cap = withinSolverLimit(kPolishInnerIterations);
  p.save.begin();
  la.copy(p.save, w.x, p.x0);
  la.copy(p.save, w.y, p.y0);
  la.copy(p.save, w.z, p.z0);
  la.copy(p.save, w.x, p.xKept);
  la.copy(p.save, w.y, p.yKept);
  p.save.end();
  // rowScales_ holds the active flags (assembleK1), rhoRows_ = rho times them (assembleK).
  p.begin.begin();
  la.copy(p.begin, p.x0, w.x);
  la.scaleRows(p.begin, rowScales_, p.y0, w.y);
  p.begin.end();
  // For the new point, with z = b the ADMM's right-hand side is the refinement's:
  //   sigma x - q + C^T (rho diag(active) b - lambda),   PCG warm-started at x;
  // for the step (ActiveSetRefinement::forSteps):
  //   -(P x + q) + C^T w,  w = -(lambda + rho diag(active) (C x - b)),   PCG from zero,
  // the residual formed before it is scaled by rho (no rho-sized terms cancel), to its
  // tolerance of ||rhs|| (no rounding floor: rhs shrinks with the step).
  // A solve that needs more continues where it stopped, not restarted: a PCG restarted
  // every few dozen iterations converges far slower on the stiff K_A. Plain refinements
  // solve to the inner solves' tolerance, those with momentum to kPolishSolveTolerance.
  const auto recordSolve = [&](Sequence& solve, Sequence& resume, double tolerance, bool forStep) {
    solve.begin();
    if (forStep) {
      la.spmv(solve, devC_, w.x, w.Cx);
      la.axpby(solve, -1.0, w.z, 1.0, w.Cx);
      la.scaleRows(solve, rhoRows_, w.Cx, w.w);
      la.axpby(solve, -1.0, w.y, -1.0, w.w);
      la.spmv(solve, devCt_, w.w, w.Ctw);
      la.spmv(solve, devP_, w.x, w.rhs);
      la.axpby(solve, 1.0, w.Ctw, -1.0, w.rhs);
      la.axpby(solve, -1.0, w.q, 1.0, w.rhs);
      solve.zero(w.xTilde.data(), std::size_t{w.xTilde.n()} * w.xTilde.m() * sizeof(double));
      solve.barrier();
    } else {
      recordRightHandSide(solve);
      la.copy(solve, w.x, w.xTilde);
    }
    recordInnerSolve(solve, cap, forStep ? SolveTarget::RightHandSide : SolveTarget::WarmStart, tolerance);
    solve.end();
    resume.begin();
    recordInnerSolve(resume, kPolishResumeIterations, SolveTarget::Continuation, tolerance, cap % 2 == 1);
    resume.end();
  };
  const double tight = settings_.linearSolver.relativeTolerance;
  recordSolve(p.solve, p.resume, tight, false);
  recordSolve(p.looseSolve, p.looseResume, kPolishSolveTolerance, false);
  recordSolve(p.stepSolve, p.stepResume, tight, true);
  recordSolve(p.looseStepSolve, p.looseStepResume, kPolishSolveTolerance, true);
  // r = diag(active) (C x - b) (in zTilde), lambda += rho r, and r's norm (NaN in x or
  // lambda reaches it).
  const auto recordUpdate = [&](Sequence& update, bool step) {
    update.begin();
    if (step) {
      la.axpby(update, 1.0, w.xTilde, 1.0, w.x);
    } else {
      la.copy(update, w.xTilde, w.x);
    }
    la.spmv(update, devC_, w.x, w.Cx);
    la.axpby(update, -1.0, w.z, 1.0, w.Cx);
    la.scaleRows(update, rowScales_, w.Cx, w.zTilde);
    la.scaleRows(update, rhoRows_, w.Cx, w.dy);
    la.axpby(update, 1.0, w.dy, 1.0, w.y);
    la.maxAbs(update, w.zTilde, w.measures, kPrimal);
    update.end();
  };
  recordUpdate(p.update, false);
  recordUpdate(p.stepUpdate, true);
}

namespace {

/// Nesterov's momentum before refinement `step` after a restart: (t_step - 1) / t_step+1
/// with t_0 = 1, t_i+1 = (1 + sqrt(1 + 4 t_i^2)) / 2 (0 for step 0).
double nesterovMomentum(int step) {
  double t = 1.0;
  for (int i = 0; i < step; ++i) t = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
  return (t - 1.0) / (0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t)));
}

}  // namespace

Sequence& AdmmKernels::recordedMomentum(int step) {
  const double beta = nesterovMomentum(step);
  Workspace& w = *workspace_;
  Workspace::Polish& p = *w.polish;
  if (p.momentum.size() <= static_cast<std::size_t>(step)) p.momentum.resize(static_cast<std::size_t>(step) + 1);
  return recordedOnce(p.momentum[static_cast<std::size_t>(step)], context_, [&](Sequence& s) {
    LinearAlgebra& la = algebra_;
    if (beta == 0.0) {
      la.copy(s, w.y, w.yPrevious);
      return;
    }
    la.copy(s, w.y, w.dy);  // dy: scratch until the update
    la.axpby(s, -beta, w.yPrevious, 1.0 + beta, w.y);
    la.copy(s, w.dy, w.yPrevious);
  });
}

bool AdmmKernels::refineActiveSet(const compute::ActiveSetRefinement& request, Eigen::MatrixXd& x,
                                  Eigen::MatrixXd& y, compute::ActiveSetRefinementInfo& info) {
  // No iterate (k = 0), or no rows to hold (m = 0: the host's unconstrained solve; the
  // device would copy empty vectors, which Vulkan forbids).
  if (!workspace_ || m_ == 0) return false;
  Workspace& w = *workspace_;
  const bool bySides = !request.sides.empty();
  if (request.active.size() != m_ ||
      (bySides ? request.sides.size() != std::size_t{m_} * w.k
               : request.targets.rows() != m_ || request.targets.cols() != w.k)) {
    throwUsage("ADMM: an active set or its targets do not match the " + std::to_string(m_) + " x " +
               std::to_string(w.k) + " constraint values");
  }
  for (const Eigen::Index c : request.columns) {
    if (c < 0 || c >= static_cast<Eigen::Index>(w.k)) throwUsage("ADMM: a polished column is out of range");
  }
  if (!w.polish) {
    w.polish = std::make_unique<Workspace::Polish>(context_, n_, m_, w.k);
    recordPolish();
  }
  Workspace::Polish& p = *w.polish;
  if (!w.polishStartSaved) {
    p.save.run();
    w.polishStartSaved = true;
  }

  if (bySides) {
    // The sides findActiveSides found are on the device already.
    const std::vector<std::uint32_t> packed = packSides(request.sides);
    if (packed != w.heldSides) {
      w.heldSides.clear();
      w.sides.upload(packed);
      w.heldSides = packed;
    }
  }
  // K_A = K0 + rho C^T diag(active) C: the ADMM's K with the active flags as row scales,
  // formed from the sides on the device when the flags are a column's sides (the polish's
  // sets are), else uploaded.
  int sidesColumn = -1;
  if (bySides && !request.columns.empty()) {
    const auto c = static_cast<std::size_t>(request.columns.front());
    bool fromSides = true;
    for (std::uint32_t i = 0; i < m_ && fromSides; ++i) {
      fromSides = (request.sides[c * m_ + i] != compute::BoundSide::Free) == (request.active[i] != 0);
    }
    if (fromSides) sidesColumn = static_cast<int>(c);
  }
  k1Current_ = false;  // K1 is the polish's from here on; the next setRho forms the ADMM's
  longFirstSolve_ = true;
  try {
    if (sidesColumn >= 0) {
      assembleK1FromRowScales(sidesColumn);
    } else {
      std::vector<double> flags(m_);
      for (std::uint32_t i = 0; i < m_; ++i) flags[i] = request.active[i] ? 1.0 : 0.0;
      assembleK1(flags);
    }
    assembleK(request.rho);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Numerical) throw;
    return true;  // not factored: the ADMM's solution stands
  }
  info.factored = true;
  if (bySides) {
    recordedOnce(p.targets, context_, [&](Sequence& s) {
      const std::uint32_t count = m_ * w.k;
      s.dispatch(polishTargets_, {w.sides, w.lower.data(), w.upper.data(), w.z.data()}, ElementCountPush{count},
                 groupsFor(context_, count));
    }).run();
  } else {
    w.z.upload(request.targets);
  }
  p.begin.run();

  // Only the relative tolerance stops these solves (no bound from ADMM residuals).
  const double noBound = std::numeric_limits<double>::max();
  w.state.upload({&noBound, 1}, kLinearTolerance2);
  w.uploadedTolerance = -1.0;
  double state[kStateSize];
  w.state.download(state);
  const double iterationsBefore = state[kInnerIterations];
  const long maxIterations = std::max(1, settings_.linearSolver.maxIterations);
  double previous = std::numeric_limits<double>::infinity();
  // The method of multipliers is gradient ascent on the multipliers, slow along the
  // constraints' small singular values: with PCG's penalty (kIterativePolishRho) the
  // ~256-face exact step's polish runs into its 30-refinement cap, its residual falling by
  // ~0.7 per refinement. Where two plain refinements show such a slow contraction (above
  // kSlowContraction), Nesterov's momentum accelerates the next ones, restarted (a plain
  // refinement that decides again) when the residual grows; a tightly solved plain
  // refinement that does not reduce it ends them (the rounding floor). Fast contractions keep the
  // plain method, whose next refinement starts at the solution within rounding. Measured
  // on that step (lavapipe, 30 refinements): residual 8.0e-12 -> 3.3e-14, polish PCG
  // iterations 2 599 -> 2 268 (BM_GlobalStep/vulkan/256; the bound in
  // VulkanAdmm.ASlowlyContractingPolishIsAcceleratedTowardsTheRoundingFloor). The
  // accelerated refinements solve only to kPolishSolveTolerance of their warm start's
  // residual.
  constexpr double kSlowContraction = 0.5;
  // A reach (ActiveSetRefinement::reach) is judged from the refinement with this index on
  // (the 11th): by then the first momentum cycle has shown the contraction (the first two
  // are plain ones that reduce the fast modes, and would promise too much).
  constexpr int kReachJudgedFrom = 10;
  // A polish with no reach (the accuracy polish after an ADMM solve) whose best residual
  // fell by less than half over the last kStagnationWindow refinements, within
  // kNearRoundingFloor of its goal, has met the rounding floor: the 2.3k-face grid's first
  // step ran into its 200-refinement cap there, residual 5.1e-14 -> 3.7e-14 over its last
  // 70 refinements (goal 1e-15), about 500 PCG iterations for nothing. Far above the goal
  // a slow contraction still pays (BoxQpSettings::inPlacePolishIterations).
  constexpr int kStagnationWindow = 10;
  constexpr double kNearRoundingFloor = 1e3;
  std::vector<double> bestSoFar;
  double first = 0.0, best = std::numeric_limits<double>::infinity();
  int sinceRestart = 0;
  bool accelerate = false;
  // The restart after an accelerated refinement that overshot is a plain refinement solved
  // loosely: the contraction is known to be slow there, and a tight solve (~100 PCG
  // iterations against ~20) would cost as much as a whole momentum cycle's others. Only a
  // tightly solved plain refinement decides the rounding floor: a loose one that does not
  // reduce the residual is followed by one. From a far start (ActiveSetRefinement::farStart)
  // every plain refinement is solved loosely too, the first ones included: there the first
  // three tight ones took ~470 of a 16x16 grid's ~1 500 PCG iterations per step, and loose
  // ones reduce the residual as much (5.4e-4 -> 2.1e-4 -> 1.7e-4 either way).
  bool looseRestart = request.farStart;
  bool steps = request.forSteps;
  int phaseStart = 0;  // the refinement the current penalty's began with
  // Loose solves for the step reach the goal in the directions the stiff active rows fix,
  // which decide the residual; the directions they leave free (where the objective
  // decides) keep the loose solves' error. So refinements for the step that reach the
  // goal loosely end with one tight refinement (its right-hand side, near the solution, is
  // the small dual residual). Measured on lavapipe (the random QP of
  // VulkanAdmm.AStiffPenaltyKeepsItsAccuracyWhenItsRefinementsSolveForTheirSteps, rho 1e8):
  // x 6.5e-10 (relative) from the active-set solution without it, 3.9e-15 with it.
  bool finishing = false;
  for (int r = 0; r < request.maxRefinements + (finishing ? 1 : 0); ++r) {
    throwIfCancelled("the polish");
    if (!accelerate) sinceRestart = 0;
    const bool plain = sinceRestart == 0;
    const bool tight = finishing || (plain && !looseRestart);
    recordedMomentum(sinceRestart++).run();
    const double solveStart = state[kInnerIterations];
    double capped = state[kCappedSolves];
    (tight ? (steps ? p.stepSolve : p.solve) : (steps ? p.looseStepSolve : p.looseSolve)).run();
    w.state.download(state);
    while (state[kCappedSolves] > capped && state[kInnerIterations] - solveStart < maxIterations) {
      capped = state[kCappedSolves];
      // continues the PCG where the capped run stopped
      (tight ? (steps ? p.stepResume : p.resume) : (steps ? p.looseStepResume : p.looseResume)).run();
      w.state.download(state);
    }
    if (state[kCappedSolves] > capped) info.solvesConverged = false;
    (steps ? p.stepUpdate : p.update).run();
    ++info.refinements;
    const std::vector<double> norms = w.measures.read();
    double residual = 0.0;
    for (const Eigen::Index c : request.columns) {
      const double value = w.measures.at(norms, kPrimal, static_cast<std::uint32_t>(c));
      residual = std::isnan(value) ? value : std::max(residual, value);
      if (std::isnan(residual)) break;
    }
    if (finishing) break;
    if (!(residual > request.goal)) {  // NaN too: the caller rejects it
      if (!steps || tight || std::isnan(residual)) break;
      finishing = true;
      accelerate = false;
      continue;
    }
    if (r == phaseStart) first = residual;
    best = std::min(best, residual);
    bestSoFar.push_back(best);
    if (request.reach == 0.0 && r >= kStagnationWindow && best < kNearRoundingFloor * request.goal &&
        best > 0.5 * bestSoFar[r - kStagnationWindow]) {
      break;
    }
    if (request.reach > 0.0 && r - phaseStart >= kReachJudgedFrom) {
      // The mean contraction per refinement at this penalty (from the best residual: the
      // momentum's overshoots come back), over the refinements left.
      const double rate = std::pow(best / first, 1.0 / (r - phaseStart));
      if (best * std::pow(rate, request.maxRefinements - 1 - r) > request.reach) {
        if (steps || !(request.stiffRho > request.rho)) break;
        // The method of multipliers goes on from this iterate and these multipliers at the
        // stiff penalty (K_A formed again; its active rows are the same).
        try {
          assembleK(request.stiffRho);
        } catch (const Error& e) {
          if (e.kind() != ErrorKind::Numerical) throw;
          break;
        }
        steps = true;
        phaseStart = r + 1;
        best = std::numeric_limits<double>::infinity();
        accelerate = false;
        looseRestart = request.farStart;
        previous = std::numeric_limits<double>::infinity();
        continue;
      }
    }
    if (residual >= previous) {
      if (tight) break;       // the rounding floor
      accelerate = false;     // restart: a plain refinement next, which decides again
      looseRestart = !plain;  // loosely after an overshoot, tightly after a loose restart
    } else if (plain) {
      accelerate = residual > kSlowContraction * previous;
      looseRestart = request.farStart;
    }
    previous = residual;
  }
  info.linearIterations = static_cast<long>(state[kInnerIterations] - iterationsBefore);
  if (!request.keepResult) {
    w.x.download(x);
    w.y.download(y);
    return true;
  }
  // The refined columns join the kept result, which becomes the iterate (columns are
  // contiguous: one copy each).
  Sequence keep(context_);
  keep.begin();
  const std::size_t xBytes = std::size_t{n_} * sizeof(double), yBytes = std::size_t{m_} * sizeof(double);
  for (const Eigen::Index c : request.columns) {
    const auto column = static_cast<std::size_t>(c);
    keep.copy(w.x.data(), p.xKept.data(), xBytes, column * xBytes, column * xBytes);
    keep.copy(w.y.data(), p.yKept.data(), yBytes, column * yBytes, column * yBytes);
  }
  keep.barrier();
  algebra_.copy(keep, p.xKept, w.x);
  algebra_.copy(keep, p.yKept, w.y);
  algebra_.copy(keep, p.z0, w.z);  // the ADMM's z again, not this refinement's targets
  keep.end();
  keep.run();
  return true;
}

bool AdmmKernels::findActiveSides(std::vector<compute::BoundSide>& sides) {
  if (!workspace_ || m_ == 0) return false;
  Workspace& w = *workspace_;
  const std::uint32_t count = m_ * w.k;
  w.heldSides.clear();  // before the run: should it fail, w.sides holds nothing known
  recordedOnce(w.findSides, context_, [&](Sequence& s) {
    s.dispatch(activeSides_, {w.z.data(), w.y.data(), w.lower.data(), w.upper.data(), w.sides}, ElementCountPush{count},
               groupsFor(context_, static_cast<std::uint32_t>(sideWords(count))));
  }).run();
  std::vector<std::uint32_t> words(sideWords(count));
  w.sides.download(words);
  sides.resize(count);
  for (std::size_t e = 0; e < count; ++e) {
    sides[e] = static_cast<compute::BoundSide>((words[e / 16] >> (2 * (e % 16))) & 3u);
  }
  w.heldSides = std::move(words);
  return true;
}

double AdmmKernels::boundViolation() {
  if (!workspace_ || m_ == 0) return 0.0;
  Workspace& w = *workspace_;
  recordedOnce(w.measureViolation, context_, [&](Sequence& s) {
    const std::uint32_t count = m_ * w.k;
    algebra_.spmv(s, devC_, w.x, w.Cx);
    s.dispatch(boundViolation_, {w.Cx.data(), w.lower.data(), w.upper.data(), w.violation.data()}, ElementCountPush{count},
               groupsFor(context_, count));
    s.barrier();
    algebra_.maxAbs(s, w.violation, w.violationNorms, 0);
  }).run();
  const std::vector<double> all = w.violationNorms.read();
  double violation = 0.0;
  for (std::uint32_t c = 0; c < w.k; ++c) {
    const double value = w.violationNorms.at(all, 0, c);
    if (std::isnan(value)) return value;
    violation = std::max(violation, value);
  }
  return violation;
}

void AdmmKernels::discardRefinement() {
  if (!workspace_ || !workspace_->polish || !workspace_->polishStartSaved) {
    throwUsage("ADMM: no refinement to discard");
  }
  Workspace& w = *workspace_;
  Workspace::Polish& p = *w.polish;
  recordedOnce(p.discard, context_, [&](Sequence& s) {
    algebra_.copy(s, p.x0, w.x);
    algebra_.copy(s, p.y0, w.y);
    algebra_.copy(s, p.z0, w.z);
    algebra_.copy(s, p.x0, p.xKept);
    algebra_.copy(s, p.y0, p.yKept);
  }).run();
}

}  // namespace plano::vk
