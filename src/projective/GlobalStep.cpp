#include "projective/GlobalStep.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::projective {
namespace {

std::string formatDouble(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

compute::DeviceMatrix scaleColumn(const std::vector<double>& scales) {
  return Eigen::Map<const Eigen::VectorXd>(scales.data(), static_cast<Eigen::Index>(scales.size()));
}

/// maps = one per four rows of x (4 #F x 3), their first three columns those rows.
void setFirstColumns(const Eigen::MatrixXd& x, std::vector<Eigen::Matrix4d>& maps) {
  maps.resize(static_cast<std::size_t>(x.rows() / 4));
  for (std::size_t f = 0; f < maps.size(); ++f) maps[f].leftCols<3>() = x.middleRows<4>(4 * static_cast<Eigen::Index>(f));
}

}  // namespace

const char* toString(GlobalStepStatus status) {
  switch (status) {
    case GlobalStepStatus::Solved: return "solved";
    case GlobalStepStatus::Unchanged: return "unchanged";
  }
  return "unknown";
}

GlobalStep::GlobalStep(compute::Backend& backend, const ShapeSpace& space, std::vector<Index> constrained,
                       const GlobalStepSettings& settings)
    : backend_(backend), space_(space), constrained_(std::move(constrained)), settings_(settings) {
  if (!(settings_.smoothness >= 0.0) || !std::isfinite(settings_.smoothness)) {
    throwUsage("global step: smoothness must be a finite number >= 0, got " + formatDouble(settings_.smoothness));
  }
  if (!(settings_.epsilonGrowth > 1.0)) throwUsage("global step: epsilon growth must exceed 1");
  if (!(settings_.compatibleViolation >= 0.0) || !std::isfinite(settings_.compatibleViolation)) {
    throwUsage("global step: the compatible violation must be a finite number >= 0");
  }
  setIntermediateAttempts(settings_.intermediateAttempts);
  std::vector<Index> slot(space_.vertexCount(), -1);
  for (std::size_t i = 0; i < constrained_.size(); ++i) {
    const Index v = constrained_[i];
    if (v < 0 || v >= space_.vertexCount()) {
      throwBadInput("global step: constrained vertex " + std::to_string(v) + " is out of range (" +
                    std::to_string(space_.vertexCount()) + " vertices)");
    }
    if (slot[v] >= 0) throwBadInput("global step: vertex " + std::to_string(v) + " is constrained twice");
    slot[v] = static_cast<Index>(i);
  }

  const auto& offsets = space_.vertexCornerOffsets();
  const auto& corners = space_.cornersOfVertex();
  for (Index v = 0; v < space_.vertexCount(); ++v) {
    const Index begin = offsets[v];
    const Index end = offsets[v + 1];
    if (slot[v] >= 0) {
      for (Index k = begin; k < end; ++k) rows_.push_back({v, corners[k], -1, slot[v]});
    } else {
      for (Index k = begin + 1; k < end; ++k) rows_.push_back({v, corners[begin], corners[k], -1});
    }
  }

  std::vector<ScaledConstraintMatrix::Term> terms;
  terms.reserve(2 * rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const Eigen::RowVector4d p = homogeneous(space_.basePositions().row(row.vertex));
    const auto i = static_cast<Index>(r);
    terms.push_back({i, space_.cornerFace(row.cornerA), p, row.cornerA});
    if (row.cornerB >= 0) terms.push_back({i, space_.cornerFace(row.cornerB), -p, row.cornerB});
  }
  constraints_ =
      ScaledConstraintMatrix(static_cast<Index>(rows_.size()), space_.faceCount(), space_.cornerCount(), terms);

  // P = I + alpha * (L kron I_4): ||A_f - A_g||^2 per column adds alpha to the (f, f),
  // (g, g) blocks and -alpha to the (f, g), (g, f) blocks of each of the 4 entries.
  const Index n = 4 * space_.faceCount();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(n) + 16 * space_.adjacentFaces().size());
  for (Index i = 0; i < n; ++i) entries.emplace_back(i, i, 1.0);
  const double alpha = settings_.smoothness;
  if (alpha > 0.0) {
    for (const auto& [f, g] : space_.adjacentFaces()) {
      for (Index r = 0; r < 4; ++r) {
        entries.emplace_back(4 * f + r, 4 * f + r, alpha);
        entries.emplace_back(4 * g + r, 4 * g + r, alpha);
        entries.emplace_back(4 * f + r, 4 * g + r, -alpha);
        entries.emplace_back(4 * g + r, 4 * f + r, -alpha);
      }
    }
  }
  P_.resize(n, n);
  P_.setFromTriplets(entries.begin(), entries.end());
}

GlobalStepInfo GlobalStep::solve(const std::vector<Eigen::Matrix4d>& targets, const Positions& positions,
                                 FaceMaps& result) {
  const Index faceCount = space_.faceCount();
  if (static_cast<Index>(targets.size()) != faceCount) {
    throwUsage("global step: " + std::to_string(targets.size()) + " target maps for " + std::to_string(faceCount) +
               " faces");
  }
  for (Index f = 0; f < faceCount; ++f) {
    if (!targets[f].allFinite()) throwNumerical("global step: the target map of face " + std::to_string(f) + " is not finite");
  }
  const std::vector<double> shat = space_.inducedReciprocalScales(targets);
  Index nonPositive = 0;
  for (Index c = 0; c < space_.cornerCount(); ++c) {
    if (shat[c] <= 0.0) ++nonPositive;
    if (!(std::abs(shat[c]) > kMinimumReciprocalScale)) {
      throwNumerical("global step: the target map of face " + std::to_string(space_.cornerFace(c)) +
                     " sends vertex " + std::to_string(space_.faces().indices()[c]) +
                     " to infinity (reciprocal scale factor " + formatDouble(shat[c]) + ")");
    }
  }
  Eigen::MatrixXd T(4 * faceCount, 3);
  for (Index f = 0; f < faceCount; ++f) T.middleRows<4>(4 * f) = targets[f].leftCols<3>();
  compute::DeviceMatrix columns;
  GlobalStepInfo info = project(compute::DeviceMatrix(std::move(T)), scaleColumn(shat), positions, columns);
  info.nonPositiveScales = nonPositive;
  setFirstColumns(columns.values(), result.maps);
  for (Index f = 0; f < faceCount; ++f) result.maps[f].col(3) = targets[f].col(3);
  result.reciprocalScales = shat;
  return info;
}

GlobalStepInfo GlobalStep::solve(const compute::DeviceProjectiveFits& fits, const Positions& positions,
                                 compute::DeviceMatrix& resultColumns) {
  const Index faceCount = space_.faceCount();
  if (fits.linearColumns.rows() != 4 * static_cast<Eigen::Index>(faceCount) || fits.linearColumns.cols() != 3 ||
      fits.reciprocalScales.rows() != space_.cornerCount() || fits.reciprocalScales.cols() != 1) {
    throwUsage("global step: projective fits of " + std::to_string(fits.linearColumns.rows()) + " x " +
               std::to_string(fits.linearColumns.cols()) + " columns and " +
               std::to_string(fits.reciprocalScales.rows()) + " scales for " + std::to_string(faceCount) +
               " faces and " + std::to_string(space_.cornerCount()) + " corners");
  }
  if (const Index c = fits.firstVanishingCorner; c >= 0) {  // the scales come over to say which
    throwNumerical("global step: the target map of face " + std::to_string(space_.cornerFace(c)) + " sends vertex " +
                   std::to_string(space_.faces().indices()[c]) + " to infinity (reciprocal scale factor " +
                   formatDouble(fits.reciprocalScales.values()(c, 0)) + ")");
  }
  GlobalStepInfo info = project(fits.linearColumns, fits.reciprocalScales, positions, resultColumns);
  info.nonPositiveScales = fits.nonPositiveScales;
  return info;
}

GlobalStepInfo GlobalStep::solveProjectiveFitsAt(const compute::DeviceMatrix& current, const Positions& positions,
                                                 compute::DeviceProjectiveFits& fits,
                                                 compute::DeviceMatrix& resultColumns) {
  backend_.fitProjectiveMapsOnDevice(space_.faces(), space_.basePositions(), current, kMinimumReciprocalScale, fits);
  return solve(fits, positions, resultColumns);
}

void GlobalStep::setIntermediateAttempts(int attempts) {
  if (attempts < 0) throwUsage("global step: the intermediate attempts must be >= 0, got " + std::to_string(attempts));
  settings_.intermediateAttempts = attempts;
}

GlobalStepInfo GlobalStep::solveAffine(const compute::DeviceMatrix& linearColumns, const Positions& positions,
                                       FaceMaps& result) {
  compute::DeviceMatrix columns;
  const GlobalStepInfo info = solveAffine(linearColumns, positions, columns);
  setFirstColumns(columns.values(), result.maps);
  for (auto& map : result.maps) map.col(3) = Eigen::Vector4d(0.0, 0.0, 0.0, 1.0);
  result.reciprocalScales.assign(space_.cornerCount(), 1.0);
  return info;
}

GlobalStepInfo GlobalStep::solveAffine(const compute::DeviceMatrix& linearColumns, const Positions& positions,
                                       compute::DeviceMatrix& resultColumns) {
  const Index faceCount = space_.faceCount();
  if (linearColumns.rows() != 4 * static_cast<Eigen::Index>(faceCount) || linearColumns.cols() != 3) {
    throwUsage("global step: affine targets of " + std::to_string(linearColumns.rows()) + " x " +
               std::to_string(linearColumns.cols()) + " for " + std::to_string(faceCount) + " faces (need 4 #F x 3)");
  }
  // Fourth columns (0, 0, 0, 1): every corner's reciprocal scale factor is 1.
  return project(linearColumns, Eigen::MatrixXd::Ones(space_.cornerCount(), 1), positions, resultColumns);
}

GlobalStepInfo GlobalStep::project(const compute::DeviceMatrix& T, const compute::DeviceMatrix& shat,
                                   const Positions& positions, compute::DeviceMatrix& x) {
  if (!constrained_.empty() && positions.rows() != static_cast<Eigen::Index>(constrained_.size())) {
    throwUsage("global step: " + std::to_string(positions.rows()) + " positions for " +
               std::to_string(constrained_.size()) + " constrained vertices");
  }

  GlobalStepInfo info;
  // C_s (values 1/shat of each row's corners) and d for columns 0..2 (d differs per column
  // only on positional rows).
  const auto m = static_cast<Eigen::Index>(rows_.size());
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(m, 3);
  std::vector<char> positional(m, 0);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Row& row = rows_[r];
    if (row.cornerB >= 0) continue;
    positional[r] = 1;
    const Eigen::RowVector3d q = space_.normalization().toNormalized(Eigen::RowVector3d(positions.row(row.constrainedSlot)));
    if (!q.allFinite()) {
      throwBadInput("global step: the position of constrained vertex " + std::to_string(row.vertex) + " is not finite");
    }
    d.row(r) = q;
  }
  // C's pattern depends on the topology (and the constrained vertices) only: one solver
  // for the object's lifetime. Scales on the host fill C here (the kept solver takes it);
  // scales on a device form C's values there.
  BoxQpSettings qpSettings = settings_.qp;
  qpSettings.preconditionerBlock = 4;  // rows 4f..4f+3: the entries of face f's map, coupled in K
  qpSettings.returnDuals = false;      // zero duals or those the ADMM keeps (solveEpsilonSchedule)
  BoxQpSolver* solver = nullptr;
  if (shat.onHost()) {
    const Eigen::MatrixXd& scales = shat.values();
    const std::span<const double> values(scales.data(), static_cast<std::size_t>(scales.size()));
    constraints_.fill(values);
    solver = &keptSolver(qp_, backend_, P_, constraints_, values, qpSettings);
  } else {
    solver = &keptSolver(qp_, backend_, P_, constraints_, shat, qpSettings);
  }
  BoxQpSolver& qp = *solver;
  compute::RelaxedBounds bounds{std::move(d), std::vector<char>(m), 0.0};
  for (Eigen::Index r = 0; r < m; ++r) bounds.relaxed[r] = !positional[r];

  solveEpsilonSchedule(qp, T, bounds, settings_, "global step", info, x, &scheduleMemory_);
  return info;
}

void solveEpsilonSchedule(BoxQpSolver& qp, const compute::DeviceMatrix& T, compute::RelaxedBounds& bounds,
                          const GlobalStepSettings& settings, const std::string& what, GlobalStepInfo& info,
                          compute::DeviceMatrix& x, EpsilonScheduleMemory* memory) {
  // q = -T; measured where the QP runs, which keeps q and d for the attempts.
  const compute::DeviceMatrix q = T.negated();
  info.initialViolation = bounds.centre.rows() > 0 ? qp.violationAt(q, bounds, T) : 0.0;
  if (!std::isfinite(info.initialViolation)) {  // d is finite: a target is not
    const Eigen::MatrixXd& values = T.values();
    for (Eigen::Index f = 0; f < values.rows() / 4; ++f) {
      if (!values.middleRows<4>(4 * f).allFinite()) {
        throwNumerical(what + ": the target map of face " + std::to_string(f) + " is not finite");
      }
    }
    throwNumerical(what + ": the targets' constraint violation is not finite");
  }

  std::vector<double> schedule;
  const bool compatible =
      settings.epsilonStart == EpsilonStart::Relaxed && info.initialViolation <= settings.compatibleViolation;
  const double eps0 = (compatible ? 1.0 : settings.initialEpsilonFraction) * info.initialViolation;
  if (settings.epsilonStart == EpsilonStart::ExactFirst || eps0 == 0.0) schedule.push_back(0.0);
  if (eps0 > 0.0) {
    double eps = eps0;
    for (int i = 0; i <= settings.maxEpsilonIncreases; ++i, eps *= settings.epsilonGrowth) {
      const bool keepsTargets = eps >= (1.0 - 1e-12) * info.initialViolation;  // eps0 * growth^i rounds
      if (keepsTargets && i > 0 && schedule.back() < (1.0 - 1e-12) * info.initialViolation) {
        // The last eps below the violation: intermediate attempts before keeping the targets.
        const double failed = schedule.back();
        const int n = settings.intermediateAttempts;
        for (int j = 1; j <= n; ++j) schedule.push_back(failed * std::pow(settings.epsilonGrowth, double(j) / (n + 1)));
      }
      schedule.push_back(eps);
    }
  }

  // Attempts at fractions of the violation that stalled in the last two steps of the loop
  // (GlobalStepSettings::stalledAttemptSkips); never an exact one, nor the last.
  const double skipFraction = memory ? std::min(memory->lastStalledFraction, memory->earlierStalledFraction) : 0.0;
  const bool skipping = skipFraction > 0.0 && settings.stalledAttemptSkips > 0 &&
                        memory->skippingSteps < settings.stalledAttemptSkips;
  double stalledFraction = skipping ? skipFraction : 0.0;
  bool solved = false;
  for (std::size_t a = 0; a < schedule.size(); ++a) {
    const double eps = schedule[a];
    if (skipping && eps > 0.0 && a + 1 < schedule.size() &&
        eps <= (1.0 + 1e-9) * skipFraction * info.initialViolation) {
      EpsilonAttempt skipped{eps, BoxQpStatus::Stalled, 0, false};
      skipped.skipped = true;
      info.attempts.push_back(skipped);
      continue;
    }
    throwIfCancelled(("the " + what).c_str());
    bounds.epsilon = eps;
    // Every attempt starts from the targets: an infeasible attempt leaves diverging duals
    // (its certificate), a poor warm start for the next eps.
    compute::DeviceMatrix xTry;
    const double startRho = qp.rho();
    const BoxQpInfo qpInfo = qp.solve(q, bounds, T, xTry);
    info.attempts.push_back({eps, qpInfo.status, qpInfo.iterations, qpInfo.direct});
    info.admmIterations += qpInfo.iterations;
    info.factorizations += qpInfo.factorizations;
    info.linearIterations += qpInfo.linearIterations;
    if (qpInfo.status == BoxQpStatus::NonFinite) {
      throwNumerical(what + ": the ADMM iteration produced a non-finite value (eps " + formatDouble(eps) + ")");
    }
    if (isSolved(qpInfo.status)) {
      x = std::move(xTry);
      info.epsilon = eps;
      info.polished = qpInfo.polished;
      info.polishRefinements = qpInfo.polishRefinements;
      info.status = startWasOptimal(qpInfo) ? GlobalStepStatus::Unchanged : GlobalStepStatus::Solved;
      solved = true;
      break;
    }
    // A stalled or capped attempt ran hundreds of iterations while its drifting duals drove
    // rho toward its clamp, where the next eps's attempt often cannot converge within the
    // cap either: the next attempt starts at the rho this one started at, as it restarts
    // from the targets and zero duals. A certified infeasible attempt stops within tens of
    // iterations with rho still in the problem's range, and the next attempt keeps it.
    // Measured on the CPU, ADMM iterations: hexagonal dome, two Catmull-Clark levels,
    // 102 550 -> 8 060; cube 5 790 -> 5 640 (Catmull-Clark), 7 160 -> 6 690 (four-point);
    // dodecahedron, four-point, 2 230 -> 5 870 (one attempt then crept toward the cap, until
    // attempts too slow to converge within it stopped as stalled too: 2 100).
    if (qpInfo.status == BoxQpStatus::Stalled || qpInfo.status == BoxQpStatus::MaxIterationsReached) {
      qp.setRho(startRho);
      if (eps > 0.0) stalledFraction = std::max(stalledFraction, eps / info.initialViolation);
    }
  }
  if (memory) {
    memory->skippingSteps = skipping ? memory->skippingSteps + 1 : 0;
    memory->earlierStalledFraction = memory->lastStalledFraction;
    memory->lastStalledFraction = stalledFraction;
  }
  if (!solved) {
    throwNumerical(what + ": no feasible relaxation found; eps grew from " + formatDouble(schedule.front()) +
                   " to " + formatDouble(schedule.back()) + " (initial violation " +
                   formatDouble(info.initialViolation) + ", " + std::to_string(info.admmIterations) +
                   " ADMM iterations)");
  }

  // Measured where the QP left x (its iterate, on a device: two scalars come back).
  info.constraintResidual = qp.centreDistance(x, bounds, true);
  info.positionalResidual = qp.centreDistance(x, bounds, false);
}

}  // namespace plano::projective
