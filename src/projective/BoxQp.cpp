#include "projective/BoxQp.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/Error.h"

namespace plano::projective {
namespace {

BoxQpStatus toBoxQpStatus(compute::AdmmStatus status) {
  switch (status) {
    case compute::AdmmStatus::Solved: return BoxQpStatus::Solved;
    case compute::AdmmStatus::PrimalInfeasible: return BoxQpStatus::PrimalInfeasible;
    case compute::AdmmStatus::MaxIterationsReached: return BoxQpStatus::MaxIterationsReached;
    case compute::AdmmStatus::NonFinite: return BoxQpStatus::NonFinite;
    case compute::AdmmStatus::Stalled: return BoxQpStatus::Stalled;
    case compute::AdmmStatus::SolvedInaccurate: return BoxQpStatus::SolvedInaccurate;
  }
  return BoxQpStatus::MaxIterationsReached;
}

/// The refinements stop once the active rows' residual is this fraction of their largest
/// target (or absolute, for targets below 1): rounding.
constexpr double kRoundingGoal = 1e-15;

/// An all-equality problem's polish with no ADMM before it (BoxQpSolver::
/// solveEqualitiesInPlace) stands once its residual is this fraction of the largest target
/// (absolute below 1): near rounding. The ADMM's tolerance is no bound there: the maps'
/// error is the residual amplified along C's softest directions (measured on the exact
/// steps of GlobalStepCase, lavapipe: about 600 times on 256 faces, 2 600 times on 1k),
/// and a 1k-face step polished from zero multipliers to a residual of 1.3e-6 (within the
/// ADMM's 1.4e-6) gave maps 3.5e-3 from the CPU's. Warm-started steps reach 3e-15 .. 7e-15.
constexpr double kEqualityPolishResidual = 1e-12;
/// Where that polish stops, as a fraction of the residual it is accepted at: near rounding
/// (warm steps reach 3e-15 .. 7e-15), whose last digits its loose solves could chase for
/// many refinements (with a cap of 200, a 16x16 grid's 8-iteration deformation took 11 616
/// PCG iterations going for kRoundingGoal, 10 263 with a cap of 60).
constexpr double kEqualityPolishGoal = 1e-2;

double infNorm(const Eigen::MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

compute::SparseMatrix identity(Eigen::Index n, double value) {
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  return I * value;
}

double boundViolation(const Eigen::MatrixXd& Cx, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper) {
  if (Cx.size() == 0) return 0.0;
  return std::max({0.0, (lower - Cx).maxCoeff(), (Cx - upper).maxCoeff()});
}

}  // namespace

const char* toString(BoxQpStatus status) {
  switch (status) {
    case BoxQpStatus::Solved: return "solved";
    case BoxQpStatus::PrimalInfeasible: return "primal_infeasible";
    case BoxQpStatus::MaxIterationsReached: return "max_iterations";
    case BoxQpStatus::NonFinite: return "non_finite";
    case BoxQpStatus::Stalled: return "stalled";
    case BoxQpStatus::SolvedInaccurate: return "solved_inaccurate";
  }
  return "unknown";
}

BoxQpSolver::BoxQpSolver(compute::Backend& backend, compute::SparseMatrix P, compute::SparseMatrix C,
                         const BoxQpSettings& settings)
    : backend_(backend), settings_(settings), P_(std::move(P)), C_(std::move(C)) {
  if (!(settings_.polishRho >= 0.0) || std::isinf(settings_.polishRho)) {
    throwUsage("box QP: the polish's rho must be a finite number >= 0 (0: automatic)");
  }
  if (!(settings_.equalityPolishStiffRho >= 0.0) || std::isinf(settings_.equalityPolishStiffRho)) {
    throwUsage("box QP: equalityPolishStiffRho (the exact-step polish's stiff rho) must be a finite number >= 0 "
               "(0: none)");
  }
  if (settings_.polishRho == 0.0) {
    settings_.polishRho = backend_.factorsSpdMatrices() ? kFactoredPolishRho : kIterativePolishRho;
  }
  C_.makeCompressed();
  if (P_.rows() != P_.cols() || C_.cols() != P_.rows()) {
    throwUsage("box QP: P is " + std::to_string(P_.rows()) + "x" + std::to_string(P_.cols()) + " and C is " +
               std::to_string(C_.rows()) + "x" + std::to_string(C_.cols()) + " (need n x n and m x n)");
  }
  admm_ = backend_.createAdmmSolver(P_, C_, static_cast<const compute::AdmmSettings&>(settings_));
}

void BoxQpSolver::setConstraintScaling(const compute::ConstraintScaling& scaling,
                                       std::span<const double> currentScales) {
  admm_->setConstraintScaling(scaling, currentScales);
  scaling_ = scaling;
  pendingScales_.reset();
}

void BoxQpSolver::setScaledConstraintValues(const compute::SparseMatrix& C, std::span<const double> scales) {
  // C comes from the matrix whose scaling the solver holds (one pattern): the sizes suffice.
  if (C.rows() != C_.rows() || C.cols() != C_.cols() || C.nonZeros() != C_.nonZeros() || !C.isCompressed()) {
    throwUsage("box QP: new constraint values on a different sparsity pattern");
  }
  admm_->setConstraintScales(scales);
  pendingScales_.reset();  // C is given whole
  // The same values (a rigid deformation's steps: every scale 1) leave the all-rows
  // factorization valid. (A C without entries may have no value array to compare.)
  const auto bytes = static_cast<std::size_t>(C.nonZeros()) * sizeof(double);
  if (bytes == 0 || std::memcmp(C.valuePtr(), C_.valuePtr(), bytes) == 0) return;
  std::copy_n(C.valuePtr(), C.nonZeros(), C_.valuePtr());
  allRowsCurrent_ = false;
}

void BoxQpSolver::setConstraintScales(const compute::DeviceMatrix& scales) {
  if (static_cast<std::size_t>(scaling_.coefficients.size()) != static_cast<std::size_t>(C_.nonZeros())) {
    throwUsage("box QP: constraint scales given before a constraint scaling");
  }
  admm_->setConstraintScales(scales);
  // C's host values follow only if a host step reads them (hostC): on a device they are
  // formed there, and the scales stay.
  pendingScales_ = scales;
  allRowsCurrent_ = false;
}

const compute::SparseMatrix& BoxQpSolver::hostC() {
  if (pendingScales_) {
    const Eigen::MatrixXd& scales = pendingScales_->values();
    compute::fillScaledValues(scaling_, {scales.data(), static_cast<std::size_t>(scales.size())}, C_.valuePtr());
    pendingScales_.reset();
  }
  return C_;
}

BoxQpInfo BoxQpSolver::solve(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower,
                             const Eigen::MatrixXd& upper, Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const BoxQpInfo info = solve(q, lower, upper, nullptr, nullptr, x, y);
  if (!settings_.returnDuals) y.resize(0, 0);
  return info;
}

BoxQpInfo BoxQpSolver::solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                             Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const BoxQpInfo info = solve(q, bounds.lower(), bounds.upper(), &bounds, nullptr, x, y);
  if (!settings_.returnDuals) y.resize(0, 0);
  return info;
}

BoxQpInfo BoxQpSolver::solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                             const compute::DeviceMatrix& start, Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const BoxQpInfo info = solve(q, bounds.lower(), bounds.upper(), &bounds, &start, x, y);
  if (!settings_.returnDuals) y.resize(0, 0);
  return info;
}

BoxQpInfo BoxQpSolver::solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                             const compute::DeviceMatrix& start, compute::DeviceMatrix& x) {
  Eigen::MatrixXd hostX, y;
  const BoxQpInfo info = solve(q, bounds.lower(), bounds.upper(), &bounds, &start, hostX, y, &x);
  return info;
}

double BoxQpSolver::centreDistance(const compute::DeviceMatrix& x, const compute::RelaxedBounds& bounds,
                                   bool relaxedRows) {
  if (!x.onHost()) {
    if (const auto measured = admm_->centreDistance(relaxedRows)) return *measured;
  }
  const Eigen::Index m = C_.rows();
  if (m == 0 || x.cols() == 0) return 0.0;
  const Eigen::MatrixXd distance = (hostC() * x.values() - bounds.centre).cwiseAbs();
  double largest = 0.0;
  for (Eigen::Index r = 0; r < m; ++r) {
    if (!relaxedRows && bounds.relaxed[static_cast<std::size_t>(r)]) continue;
    const double value = distance.row(r).maxCoeff<Eigen::PropagateNaN>();
    if (std::isnan(value)) return value;
    largest = std::max(largest, value);
  }
  return largest;
}

double BoxQpSolver::violationAt(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                                const compute::DeviceMatrix& x) {
  return admm_->violationAt(q, bounds, x, [this]() -> const compute::SparseMatrix& { return hostC(); });
}

BoxQpInfo BoxQpSolver::solve(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower,
                             const Eigen::MatrixXd& upper, const compute::RelaxedBounds* relaxed,
                             const compute::DeviceMatrix* start, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                             compute::DeviceMatrix* kept) {
  const bool allEqualities = lower.size() > 0 && lower == upper;
  const bool held = std::exchange(equalityIterateHeld_, false);
  compute::WarmStart warm = compute::WarmStart::Given;
  // The work of an equality solve on the device that fell back to the ADMM, counted in its info.
  BoxQpInfo spent;
  if (allEqualities) {
    const bool direct = settings_.equalitySolve == EqualitySolve::Direct ||
                        (settings_.equalitySolve == EqualitySolve::Automatic && backend_.factorsSpdMatrices());
    BoxQpInfo info;
    if (direct) {
      // The direct solve runs here: it reads the values (a device matrix's copy comes over).
      if (start) x = start->values();
      if (solveEqualities(q.values(), lower, x, y, info)) {
        if (kept) *kept = compute::DeviceMatrix(std::move(x));
        return info;
      }
    }
    if (settings_.warmStartEqualities && held && y.size() == 0) {
      // The last solve's iterate and rho (BoxQpSettings::warmStartEqualities).
      warm = compute::WarmStart::Kept;
    } else {
      // From zero multipliers, the ADMM of an all-equality problem starts at the initial
      // rho, not at the one the last solve ended at (raised there by the stiff rows): on a
      // 16-face deformation (21 steps at ε = 0) on lavapipe the same 430 ADMM iterations,
      // but 45 901 -> 18 358 PCG iterations in its solves with K, which that rho made
      // stiffer (4.8 -> 2.5 s).
      admm_->setRho(settings_.rho);
    }
    // The polish's method of multipliers where the ADMM's kernels keep the iterate, with no
    // ADMM iteration: from a loop's last solve's multipliers, given ones, or zero ones.
    if (!direct && settings_.equalitySolve == EqualitySolve::Automatic && settings_.polish &&
        !equalityPolishFellShort_) {
      const compute::AdmmInfo loaded = start ? admm_->load(q, lower, upper, relaxed, *start, y, warm)
                                             : admm_->load(q, lower, upper, relaxed, x, y, warm);
      if (solveEqualitiesInPlace(loaded, lower, info)) {
        return finishSolve(info, lower, upper, allEqualities, true, x, y, kept);
      }
      // The ADMM then starts from the same point, and solves this solver's later exact steps.
      spent = info;
      equalityPolishFellShort_ = true;
    }
  }
  const compute::AdmmInfo admm = start ? admm_->iterate(q, lower, upper, relaxed, *start, y, warm)
                                       : admm_->iterate(q, lower, upper, relaxed, x, y, warm);
  BoxQpInfo info;
  info.status = toBoxQpStatus(admm.status);
  info.iterations = admm.iterations + spent.iterations;
  info.factorizations = admm.factorizations + spent.factorizations;
  info.linearIterations = admm.linearIterations + spent.linearIterations;
  info.polishRefinements = spent.polishRefinements;
  info.primalResidual = admm.primalResidual;
  info.dualResidual = admm.dualResidual;
  info.rho = admm.rho;
  const bool polishing = isSolved(info.status) && settings_.polish && info.iterations > 0;
  if (polishing && polishInPlace(lower, upper, info, {settings_.inPlacePolishIterations})) {
    return finishSolve(info, lower, upper, allEqualities, true, x, y, kept);
  }
  if (polishing) {
    Eigen::MatrixXd z;  // the host's polish needs the whole iterate
    admm_->download(x, y, z);
    info.polished = polish(q.values(), lower, upper, z, x, y, info.polishRefinements);
    return finishSolve(info, lower, upper, allEqualities, false, x, y, kept);
  }
  return finishSolve(info, lower, upper, allEqualities, true, x, y, kept);
}

BoxQpInfo BoxQpSolver::finishSolve(BoxQpInfo& info, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                                   bool allEqualities, bool fetch, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                                   compute::DeviceMatrix* kept) {
  // The solution where the ADMM keeps its iterate (`kept`: left there when the ADMM's
  // kernels can), else downloaded.
  bool onDevice = false;
  if (fetch) {
    std::optional<compute::DeviceMatrix> solution;
    if (kept && !settings_.returnDuals) solution = admm_->solution();
    if (solution) {
      *kept = std::move(*solution);
      onDevice = true;
    } else {
      admm_->downloadSolution(x, settings_.returnDuals ? &y : nullptr);
    }
  }
  // On the device the kernels measure it at the iterate they keep: the solution.
  info.maxBoundViolation = onDevice ? admm_->boundViolation() : boundViolation(hostC() * x, lower, upper);
  equalityIterateHeld_ = allEqualities && isSolved(info.status);
  if (info.polished) info.primalResidual = info.maxBoundViolation;
  if (kept && !onDevice) *kept = compute::DeviceMatrix(std::move(x));
  return info;
}

bool BoxQpSolver::solveEqualitiesInPlace(const compute::AdmmInfo& loaded, const Eigen::MatrixXd& bounds,
                                         BoxQpInfo& info) {
  info = BoxQpInfo();
  info.direct = true;
  info.rho = loaded.rho;
  info.primalResidual = loaded.primalResidual;
  info.dualResidual = loaded.dualResidual;
  // A start that solves the problem comes back as given, as from the ADMM's first check.
  if (loaded.status == compute::AdmmStatus::Solved) {
    info.status = BoxQpStatus::Solved;
    return true;
  }
  const double largestTarget = bounds.size() > 0 ? bounds.cwiseAbs().maxCoeff() : 0.0;
  const double accepted = kEqualityPolishResidual * std::max(1.0, largestTarget);
  InPlacePolish how{settings_.equalityPolishIterations};
  how.reach = accepted;
  how.farStart = true;
  how.goal = kEqualityPolishGoal * accepted;
  how.stiffRho = settings_.equalityPolishStiffRho;
  if (!polishInPlace(bounds, bounds, info, how)) {
    return false;  // the kernels cannot: untouched
  }
  info.factorizations = 1;  // K_A, as a direct solve's
  // Not formed (not positive definite) or no better: discarded already.
  if (!info.polished) return false;
  if (!(admm_->boundViolation() <= accepted)) {
    admm_->discardRefinement();
    info.polished = false;
    return false;
  }
  info.status = BoxQpStatus::Solved;
  return true;
}

bool BoxQpSolver::polishInPlace(const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper, BoxQpInfo& info,
                                const InPlacePolish& how) {
  std::vector<compute::BoundSide> sides;
  if (!admm_->findActiveSides(sides)) return false;
  const Eigen::Index m = C_.rows();
  const Eigen::Index k = lower.cols();
  // Column c's active set: its rows not free.
  const auto activeOf = [&](Eigen::Index c) {
    std::vector<char> active(m);
    for (Eigen::Index i = 0; i < m; ++i) active[i] = sides[c * m + i] != compute::BoundSide::Free;
    return active;
  };
  const double before = admm_->boundViolation();
  std::vector<char> done(k, 0);
  for (Eigen::Index first = 0; first < k; ++first) {
    if (done[first]) continue;
    // Columns with the same active set share one refinement; the kernels merge the sets'.
    const std::vector<char> active = activeOf(first);
    std::vector<Eigen::Index> columns;
    double largestTarget = 0.0;
    for (Eigen::Index c = first; c < k; ++c) {
      if (done[c] || activeOf(c) != active) continue;
      columns.push_back(c);
      done[c] = 1;
      for (Eigen::Index i = 0; i < m; ++i) {
        const compute::BoundSide side = sides[c * m + i];
        if (side == compute::BoundSide::Lower) largestTarget = std::max(largestTarget, std::abs(lower(i, c)));
        if (side == compute::BoundSide::Upper) largestTarget = std::max(largestTarget, std::abs(upper(i, c)));
      }
    }
    compute::ActiveSetRefinement request{active,
                                         Eigen::MatrixXd(),
                                         columns,
                                         settings_.polishRho,
                                         how.maxRefinements,
                                         std::max(how.goal, kRoundingGoal * std::max(1.0, largestTarget)),
                                         sides,
                                         true};
    request.reach = how.reach;
    request.farStart = how.farStart;
    request.stiffRho = how.stiffRho;
    compute::ActiveSetRefinementInfo refined;
    Eigen::MatrixXd unusedX, unusedY;
    if (!admm_->refineActiveSet(request, unusedX, unusedY, refined)) {
      if (first == 0) return false;  // declined at once: the iterate is untouched
      throwUsage("box QP: the ADMM's kernels declined a polish they had begun");
    }
    info.polishRefinements += refined.refinements;
    info.linearIterations += refined.linearIterations;
    // The stiff polish system can be too ill-conditioned to form; polishing is an optional
    // refinement, so the ADMM's solution stands.
    if (!refined.factored) {
      admm_->discardRefinement();
      return true;
    }
  }
  // A polish that leaves the bounds more violated (or non-finite: NaN fails the test) is
  // discarded.
  const double after = admm_->boundViolation();
  if (!(after <= std::max(before, 1e-12))) {
    admm_->discardRefinement();
    return true;
  }
  info.polished = true;
  return true;
}

bool BoxQpSolver::polish(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                         const Eigen::MatrixXd& z, Eigen::MatrixXd& x, Eigen::MatrixXd& y, int& refinements) {
  const Eigen::Index m = C_.rows();
  const Eigen::Index k = q.cols();
  const double before = boundViolation(hostC() * x, lower, upper);

  // Active set per column, as in OSQP: equality rows, and rows whose dual pushes z onto a
  // bound; the bound is the row's target.
  std::vector<std::vector<char>> active(k, std::vector<char>(m, 0));
  Eigen::MatrixXd targets = Eigen::MatrixXd::Zero(m, k);
  for (Eigen::Index c = 0; c < k; ++c) {
    for (Eigen::Index i = 0; i < m; ++i) {
      const double l = lower(i, c), u = upper(i, c);
      if (l == u || z(i, c) - l < -y(i, c)) {
        active[c][i] = 1;
        targets(i, c) = l;
      } else if (u - z(i, c) < y(i, c)) {
        active[c][i] = 1;
        targets(i, c) = u;
      }
    }
  }

  Eigen::MatrixXd xPolished = x;
  Eigen::MatrixXd yPolished = y;  // the ADMM duals warm-start the multipliers
  // A factorization solves for the steps at the same cost, to rounding; solving for the
  // new points lost ~5e-7 to the rounding of rhoP-sized right-hand sides (measured
  // against the direct equality solve on a random QP). An iterative solve warm-started at
  // the ADMM's x solves for the points, cheaply (see solveActiveSet).
  const Refinement form = backend_.factorsSpdMatrices() ? Refinement::ForSteps : Refinement::ForPoints;
  std::vector<char> done(k, 0);
  for (Eigen::Index first = 0; first < k; ++first) {
    if (done[first]) continue;
    // Columns with the same active set (every column of an all-equality problem) share
    // one factorization and one multi-column solve per refinement.
    std::vector<Eigen::Index> columns;
    for (Eigen::Index c = first; c < k; ++c) {
      if (!done[c] && active[c] == active[first]) {
        columns.push_back(c);
        done[c] = 1;
      }
    }
    // Where the ADMM's kernels keep the iterate (the device), they refine it there.
    compute::ActiveSetRefinement request{active[first], targets, columns, settings_.polishRho,
                                         settings_.polishIterations, 0.0, {}, false};
    double largestTarget = 0.0;
    for (const Eigen::Index c : columns) {
      for (Eigen::Index i = 0; i < m; ++i) {
        if (active[first][i]) largestTarget = std::max(largestTarget, std::abs(targets(i, c)));
      }
    }
    request.goal = kRoundingGoal * std::max(1.0, largestTarget);
    compute::ActiveSetRefinementInfo refined;
    Eigen::MatrixXd xRefined, yRefined;
    if (admm_->refineActiveSet(request, xRefined, yRefined, refined)) {
      refinements += refined.refinements;
      if (!refined.factored) return false;
      for (const Eigen::Index c : columns) {
        xPolished.col(c) = xRefined.col(c);
        yPolished.col(c) = yRefined.col(c);
      }
      continue;
    }
    const ActiveSetSolve solved = solveActiveSet(active[first], columns, q, targets, form, xPolished, yPolished);
    refinements += solved.refinements;
    // The stiff polish system can be too ill-conditioned to factor; polishing is an
    // optional refinement, so the ADMM solution stands.
    if (!solved.factored) return false;
  }
  if (!xPolished.allFinite()) return false;
  const double after = boundViolation(hostC() * xPolished, lower, upper);
  if (!(after <= std::max(before, 1e-12))) return false;
  x = xPolished;
  y = yPolished;
  return true;
}

bool BoxQpSolver::solveEqualities(const Eigen::MatrixXd& q, const Eigen::MatrixXd& d, Eigen::MatrixXd& x,
                                  Eigen::MatrixXd& y, BoxQpInfo& info) {
  const Eigen::Index n = P_.rows();
  const Eigen::Index m = C_.rows();
  const Eigen::Index k = q.cols();
  Eigen::MatrixXd xs = x.size() > 0 ? x : Eigen::MatrixXd::Zero(n, k);
  Eigen::MatrixXd ys = y.size() > 0 ? y : Eigen::MatrixXd::Zero(m, k);

  // The ADMM's convergence test (compute/Admm.cpp) per column, on x and the multipliers.
  const auto norm = [](const Eigen::MatrixXd& m, Eigen::Index c) { return m.col(c).lpNorm<Eigen::Infinity>(); };
  const auto primalTolerance = [&](const Eigen::MatrixXd& Cx, Eigen::Index c) {
    return settings_.absoluteTolerance + settings_.relativeTolerance * std::max(norm(Cx, c), norm(d, c));
  };
  const auto converged = [&](const Eigen::MatrixXd& xv, const Eigen::MatrixXd& yv, bool checkDual) {
    const Eigen::MatrixXd Cx = hostC() * xv;
    const Eigen::MatrixXd Px = P_ * xv;
    const Eigen::MatrixXd Cty = hostC().transpose() * yv;
    const Eigen::MatrixXd primal = Cx - d;
    const Eigen::MatrixXd dual = Px + q + Cty;
    info.primalResidual = infNorm(primal);
    info.dualResidual = infNorm(dual);
    for (Eigen::Index c = 0; c < k; ++c) {
      if (!(norm(primal, c) <= primalTolerance(Cx, c))) return false;
      const double dualScale = std::max({norm(Px, c), norm(Cty, c), norm(q, c)});
      const double dualTolerance = compute::dualToleranceFor(settings_, dualScale);
      if (checkDual && !(norm(dual, c) <= dualTolerance)) return false;
    }
    return true;
  };

  const auto accept = [&]() {
    info.status = BoxQpStatus::Solved;
    info.maxBoundViolation = info.primalResidual;
    x = xs;
    y = ys;
    return true;
  };
  info.direct = true;
  info.rho = admm_->rho();
  // Warm starts that already solve the problem come back as given, as from the ADMM's
  // first check.
  if (converged(xs, ys, true)) return accept();

  std::vector<Eigen::Index> columns(static_cast<std::size_t>(k));
  for (Eigen::Index c = 0; c < k; ++c) columns[static_cast<std::size_t>(c)] = c;
  const ActiveSetSolve solved = solveActiveSet(std::vector<char>(m, 1), columns, q, d, Refinement::ForSteps, xs, ys);
  info.polishRefinements = solved.refinements;
  info.factorizations = solved.newlyFactored ? 1 : 0;
  if (!solved.factored || !solved.solvesConverged || !xs.allFinite() || !ys.allFinite()) return false;

  // The multipliers' stationarity holds to sigma times the last step by construction; the
  // constraints decide.
  if (converged(xs, ys, false)) return accept();
  // The residual stopped shrinking above the tolerance. Inconsistent constraints leave the
  // least-squares residual r = Cx - d, orthogonal to C's range, and the multipliers grow
  // along it: OSQP's certificate with dy = r (C^T dy ~ 0 and, l = u = d, d^T dy =
  // -||r||^2 < 0). The warm starts stay as given for the relaxed attempts.
  const Eigen::MatrixXd Cx = hostC() * xs;
  const Eigen::MatrixXd r = Cx - d;
  const Eigen::MatrixXd Ctr = hostC().transpose() * r;
  const double tolerance = settings_.infeasibilityTolerance;
  for (Eigen::Index c = 0; c < k; ++c) {
    const double size = norm(r, c);
    const bool certified = norm(Ctr, c) <= tolerance * size && d.col(c).dot(r.col(c)) < -tolerance * size;
    if (size > primalTolerance(Cx, c) && certified) {
      info.status = BoxQpStatus::PrimalInfeasible;
      info.maxBoundViolation = info.primalResidual;
      return true;
    }
  }
  return false;
}

BoxQpSolver::ActiveSetSolve BoxQpSolver::solveActiveSet(const std::vector<char>& active,
                                                        const std::vector<Eigen::Index>& columns,
                                                        const Eigen::MatrixXd& q, const Eigen::MatrixXd& targets,
                                                        Refinement form, Eigen::MatrixXd& x,
                                                        Eigen::MatrixXd& y) {
  const Eigen::Index n = P_.rows();
  const Eigen::Index m = C_.rows();
  const auto g = static_cast<Eigen::Index>(columns.size());
  ActiveSetSolve result;
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (active[i]) entries.emplace_back(static_cast<Eigen::Index>(entries.size()), i, 1.0);
  }
  compute::SparseMatrix selector(static_cast<Eigen::Index>(entries.size()), m);
  selector.setFromTriplets(entries.begin(), entries.end());
  const compute::SparseMatrix CA = selector * hostC();
  const compute::SparseMatrix CAt = CA.transpose();
  const double rhoP = settings_.polishRho;
  const bool allRows = CA.rows() == m;
  std::unique_ptr<compute::SpdSolver> created;
  compute::SpdSolver* solver = nullptr;
  if (allRows && allRowsSolver_ && allRowsCurrent_) {
    // K = P + sigma I + rhoP C^T C of the values it was factored for: solve with it as it is.
    solver = allRowsSolver_.get();
  } else {
    if (allRows) allRowsCurrent_ = false;
    const compute::SparseMatrix K = P_ + identity(n, settings_.sigma) + compute::SparseMatrix(rhoP * (CAt * CA));
    try {
      if (allRows && allRowsSolver_ && allRowsSolver_->refactor(K)) {
        solver = allRowsSolver_.get();
      } else {
        compute::LinearSolverSettings linear = settings_.linearSolver;
        linear.measureResidual = false;  // the refinements check their own constraint residual
        linear.preconditionerBlock = settings_.preconditionerBlock;  // an iterative backend's
        created = backend_.createSpdSolver(K, linear);
        solver = created.get();
      }
    } catch (const OutOfMemory&) {
      throw;  // the ADMM's K, with C's whole pattern, would not fit either
    } catch (const Error&) {
      return result;
    }
    result.newlyFactored = true;
    // Only a factorization has something to keep (its analysis, reused by refactor); an
    // iterative backend's solver would hold its copy of K on the device between steps.
    if (allRows && created && backend_.factorsSpdMatrices()) allRowsSolver_ = std::move(created);
    if (allRows && solver == allRowsSolver_.get()) allRowsCurrent_ = true;
  }
  result.factored = true;

  Eigen::MatrixXd qg(n, g), xg(n, g), b(CA.rows(), g), lambda(CA.rows(), g);
  for (Eigen::Index j = 0; j < g; ++j) {
    qg.col(j) = q.col(columns[j]);
    xg.col(j) = x.col(columns[j]);
    b.col(j) = selector * targets.col(columns[j]);
    lambda.col(j) = selector * y.col(columns[j]);
  }
  // Each refinement shrinks the active rows' residual by a factor (~20 on the cube's and
  // small grids' steps) until rounding (~1e-14) is reached, after which it only wanders:
  // the refinement stops at the first one that does not shrink it. (A fixed 30
  // refinements spent most of them there.) A refinement solves
  //   K x' = sigma x - q - C_A^T lambda + rhoP C_A^T b             (for the new point), or
  //   K dx = -(P x + q + C_A^T lambda) - rhoP C_A^T (C_A x - b)    (for the step),
  // one x' = x + dx. A factorization gives both alike. An iterative solve's tolerance is
  // relative to the right-hand side: the first's, dominated by rhoP C_A^T b, leaves errors
  // far above the solution's (1e-4 of the diagonal from a cold start on a small grid) but
  // is cheap from a warm start near the solution (the polish's, the ADMM's x); the
  // second's shrinks as the refinements converge, accurate, but each solve starts cold
  // (measured on lavapipe with Jacobi PCG: the multires deformation agreement test
  // 4.8 -> 28 s). Even a factorization rounds the first form's rhoP-sized values.
  Eigen::MatrixXd r = CA * xg - b;
  const Eigen::MatrixXd CAtb = form == Refinement::ForPoints ? Eigen::MatrixXd(rhoP * (CAt * b)) : Eigen::MatrixXd();
  const double goal = kRoundingGoal * std::max(1.0, infNorm(b));
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it < settings_.polishIterations; ++it) {
    if (form == Refinement::ForSteps) {
      const Eigen::MatrixXd rhs = -(P_ * xg + qg + CAt * lambda) - rhoP * (CAt * r);
      Eigen::MatrixXd step = Eigen::MatrixXd::Zero(n, g);
      if (!solver->solve(rhs, step).converged) result.solvesConverged = false;
      xg += step;
    } else {
      const Eigen::MatrixXd rhs = settings_.sigma * xg - qg - CAt * lambda + CAtb;
      if (!solver->solve(rhs, xg).converged) result.solvesConverged = false;
    }
    ++result.refinements;
    r = CA * xg - b;
    lambda += rhoP * r;
    const double residual = infNorm(r);
    if (residual <= goal || residual >= previous) break;
    previous = residual;
  }
  for (Eigen::Index j = 0; j < g; ++j) {
    x.col(columns[j]) = xg.col(j);
    y.col(columns[j]) = selector.transpose() * lambda.col(j);
  }
  return result;
}

BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, const compute::DeviceMatrix& scales,
                        const BoxQpSettings& settings) {
  if (!kept) {
    kept = std::make_unique<BoxQpSolver>(backend, P, C.matrix(), settings);  // C's pattern; its values follow
    kept->setConstraintScaling(C.scaling());
  }
  kept->setConstraintScales(scales);
  return *kept;
}

BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, std::span<const double> scales,
                        const BoxQpSettings& settings) {
  if (kept) {
    kept->setScaledConstraintValues(C.matrix(), scales);
  } else {
    kept = std::make_unique<BoxQpSolver>(backend, P, C.matrix(), settings);
    kept->setConstraintScaling(C.scaling(), scales);  // C's values are those of `scales`
  }
  return *kept;
}

}  // namespace plano::projective
