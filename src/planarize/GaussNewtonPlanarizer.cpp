#include "planarize/GaussNewtonPlanarizer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "compute/SparsePattern.h"
#include "core/Error.h"
#include "core/Timing.h"
#include "mesh/Planarity.h"
#include "planarize/Monitor.h"
#include "planarize/Problem.h"

namespace plano::planarize {
namespace detail {

/// Private caches of GaussNewtonPlanarizer: constraint rows, the pattern of J J^T and the
/// slots each vertex's incidences write into, and per-iteration Jacobian and residuals.
struct GaussNewtonWorkspace {
  std::vector<std::array<Index, 4>> rows;  ///< Corners a, b, c, d of each run of four.
  /// Per vertex (CSR): the (row, corner) pairs of the rows it takes part in; empty when fixed.
  std::vector<int> incidenceOffset;
  std::vector<std::pair<int, int>> incidences;
  compute::SparseMatrix system;  ///< #rows square: J J^T + nu I.
  std::vector<int> pairSlots;    ///< Per vertex, n_v^2 value indices (incidence p, incidence q).
  std::vector<int> pairSlotOffset;
  std::vector<int> diagonalSlots;
  std::vector<Eigen::Matrix<double, 4, 3>> jacobian;  ///< Per row: gradient rows of its corners.
  Eigen::VectorXd residual;                             ///< Per row: signed c_j.
  Eigen::MatrixXd rhs, dual;                            ///< #rows x 1.
  Positions step;                                       ///< #V x 3.
  std::unique_ptr<compute::SpdSolver> solver;           ///< Refactored each iteration.
};

namespace {

void buildRows(const Problem& problem, GaussNewtonWorkspace& ws) {
  const FaceList& faces = *problem.faces;
  const Index vertexCount = static_cast<Index>(problem.freeIndex.size());
  for (Index f : problem.constrainedFaces) {
    const auto face = faces[f];
    const std::size_t k = face.size();
    const std::size_t runs = (k == 4) ? 1 : k;
    for (std::size_t i = 0; i < runs; ++i) {
      ws.rows.push_back({face[i], face[(i + 1) % k], face[(i + 2) % k], face[(i + 3) % k]});
    }
  }
  std::vector<int> count(static_cast<std::size_t>(vertexCount) + 1, 0);
  for (const auto& row : ws.rows)
    for (Index v : row)
      if (problem.freeIndex[v] >= 0) ++count[v + 1];
  for (Index v = 0; v < vertexCount; ++v) count[v + 1] += count[v];
  ws.incidenceOffset = count;
  ws.incidences.resize(static_cast<std::size_t>(count.back()));
  std::vector<int> cursor(count.begin(), count.end() - 1);
  for (std::size_t j = 0; j < ws.rows.size(); ++j)
    for (int corner = 0; corner < 4; ++corner) {
      const Index v = ws.rows[j][corner];
      if (problem.freeIndex[v] >= 0) ws.incidences[cursor[v]++] = {static_cast<int>(j), corner};
    }

  const Index n = static_cast<Index>(ws.rows.size());
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index j = 0; j < n; ++j) triplets.emplace_back(j, j, 0.0);
  for (Index v = 0; v < vertexCount; ++v)
    for (int p = ws.incidenceOffset[v]; p < ws.incidenceOffset[v + 1]; ++p)
      for (int q = ws.incidenceOffset[v]; q < ws.incidenceOffset[v + 1]; ++q)
        triplets.emplace_back(ws.incidences[p].first, ws.incidences[q].first, 0.0);
  ws.system.resize(n, n);
  ws.system.setFromTriplets(triplets.begin(), triplets.end());
  ws.system.makeCompressed();
  ws.diagonalSlots.resize(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j) ws.diagonalSlots[j] = compute::storedEntryIndex(ws.system, j, j);
  ws.pairSlotOffset.assign(static_cast<std::size_t>(vertexCount) + 1, 0);
  for (Index v = 0; v < vertexCount; ++v) {
    ws.pairSlotOffset[v] = static_cast<int>(ws.pairSlots.size());
    for (int p = ws.incidenceOffset[v]; p < ws.incidenceOffset[v + 1]; ++p)
      for (int q = ws.incidenceOffset[v]; q < ws.incidenceOffset[v + 1]; ++q)
        ws.pairSlots.push_back(compute::storedEntryIndex(ws.system, ws.incidences[p].first, ws.incidences[q].first));
  }
  ws.pairSlotOffset[vertexCount] = static_cast<int>(ws.pairSlots.size());
  ws.jacobian.resize(ws.rows.size());
  ws.residual.resize(n);
}

/// Residuals and Jacobian rows at Y; returns the merit sum c_j^2.
/// A run with parallel diagonals has no usable gradient: its row is zero this iteration
/// (its planarity still counts in the merit).
double linearize(const Problem& problem, const Positions& Y, GaussNewtonWorkspace& ws) {
  double merit = 0.0;
  for (std::size_t j = 0; j < ws.rows.size(); ++j) {
    const auto& r = ws.rows[j];
    const Eigen::Vector3d a = Y.row(r[0]), b = Y.row(r[1]), c = Y.row(r[2]), d = Y.row(r[3]);
    const Eigen::Vector3d d1 = c - a, d2 = d - b, e = b - a;
    const Eigen::Vector3d m = d1.cross(d2);
    const double mNorm = m.norm();
    const double meanDiagonal = 0.5 * (d1.norm() + d2.norm());
    Eigen::Matrix<double, 4, 3>& J = ws.jacobian[j];
    if (!(mNorm > 1e-14 * d1.norm() * d2.norm()) || !(meanDiagonal > 0.0)) {
      J.setZero();
      ws.residual[static_cast<Index>(j)] = 0.0;
      const double p = quadPlanarity(a, b, c, d) / 100.0;
      merit += p * p;
      continue;
    }
    const double factor = 1.0 / (mNorm * meanDiagonal);
    const double value = e.dot(m) * factor;
    ws.residual[static_cast<Index>(j)] = value;
    merit += value * value;
    // Exact gradient of c = V / (|m| L): the triple product V = e.(d1 x d2) over its
    // normalization. Dropping the normalization's gradient (exact only at c = 0) left a
    // few near-degenerate faces of subdivided meshes stuck above 0.1 %.
    const Eigen::Vector3d u = m / mNorm;
    const Eigen::Vector3d gd1 = d2.cross(u) / mNorm + 0.5 * d1 / (d1.norm() * meanDiagonal);
    const Eigen::Vector3d gd2 = u.cross(d1) / mNorm + 0.5 * d2 / (d2.norm() * meanDiagonal);
    J.row(0) = (-(m + d2.cross(e)) * factor + value * gd1).transpose();
    J.row(1) = ((m - e.cross(d1)) * factor + value * gd2).transpose();
    J.row(2) = (d2.cross(e) * factor - value * gd1).transpose();
    J.row(3) = (e.cross(d1) * factor - value * gd2).transpose();
    for (int corner = 0; corner < 4; ++corner)
      if (problem.freeIndex[r[corner]] < 0) J.row(corner).setZero();
  }
  return merit;
}

/// Assemble J J^T + softening I and c + J dx0; solve; write the step dx = dx0 - J^T y into ws.step.
compute::LinearSolveInfo computeStep(const Problem& problem, const Positions& Y, double pullBack, double softening,
                                     compute::Backend& backend, GaussNewtonWorkspace& ws) {
  const double nu = softening;
  const Index vertexCount = static_cast<Index>(problem.freeIndex.size());
  ws.step.setZero(vertexCount, 3);
  for (Index v = 0; v < vertexCount; ++v) {
    if (problem.freeIndex[v] >= 0) ws.step.row(v) = pullBack * (problem.input.row(v) - Y.row(v));
  }
  double* values = ws.system.valuePtr();
  std::fill(values, values + ws.system.nonZeros(), 0.0);
  for (int slot : ws.diagonalSlots) values[slot] += nu;
  ws.rhs = ws.residual;
  for (Index v = 0; v < vertexCount; ++v) {
    const int begin = ws.incidenceOffset[v], end = ws.incidenceOffset[v + 1];
    const int* slots = ws.pairSlots.data() + ws.pairSlotOffset[v];
    const int count = end - begin;
    for (int p = 0; p < count; ++p) {
      const auto [row, corner] = ws.incidences[begin + p];
      const Eigen::RowVector3d gp = ws.jacobian[row].row(corner);
      ws.rhs(row, 0) += gp.dot(ws.step.row(v));
      for (int q = 0; q < count; ++q) {
        const auto [otherRow, otherCorner] = ws.incidences[begin + q];
        values[slots[p * count + q]] += gp.dot(ws.jacobian[otherRow].row(otherCorner));
      }
    }
  }
  // J J^T changes with every linearization but keeps its pattern: refactor, reusing the
  // ordering and symbolic analysis where the backend can (measured 20-35 % faster per
  // iteration on the CPU than a fresh solver). Reusing an old factor as a preconditioner
  // of conjugate gradients instead was tried and failed: with the tiny softening the
  // matrix's small eigenvalues move too much between iterations (relative residual 0.5
  // after 8 steps on spot_quad).
  ws.dual.setZero(ws.system.rows(), 1);
  if (!ws.solver || !ws.solver->refactor(ws.system)) {
    ws.solver = backend.createSpdSolver(ws.system, compute::LinearSolverSettings{});
  }
  const compute::LinearSolveInfo info = ws.solver->solve(ws.rhs, ws.dual);
  for (Index v = 0; v < vertexCount; ++v) {
    for (int p = ws.incidenceOffset[v]; p < ws.incidenceOffset[v + 1]; ++p) {
      const auto [row, corner] = ws.incidences[p];
      ws.step.row(v) -= ws.dual(row, 0) * ws.jacobian[row].row(corner);
    }
  }
  return info;
}

/// Chord (simplified Newton) step of the projection with the current factor and Jacobian J_k
/// on the residuals `residual` of a later point: dx = -J_k^T (J_k J_k^T + nu I)^-1 c.
/// One back-substitution, no factorization.
void correctorStep(const Problem& problem, const std::vector<Eigen::Matrix<double, 4, 3>>& jacobian,
                   const Eigen::VectorXd& residual, GaussNewtonWorkspace& ws) {
  const Index vertexCount = static_cast<Index>(problem.freeIndex.size());
  ws.rhs = residual;
  ws.dual.setZero(ws.system.rows(), 1);
  ws.solver->solve(ws.rhs, ws.dual);
  ws.step.setZero(vertexCount, 3);
  for (Index v = 0; v < vertexCount; ++v) {
    for (int p = ws.incidenceOffset[v]; p < ws.incidenceOffset[v + 1]; ++p) {
      const auto [row, corner] = ws.incidences[p];
      ws.step.row(v) -= ws.dual(row, 0) * jacobian[row].row(corner);
    }
  }
}

}  // namespace
}  // namespace detail

GaussNewtonPlanarizer::GaussNewtonPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                                             compute::Backend& backend)
    : settings_(settings), backend_(&backend) {
  const auto start = SteadyClock::now();
  problem_ = std::make_unique<detail::Problem>(detail::makeProblem(faces, input, settings));
  workspace_ = std::make_unique<detail::GaussNewtonWorkspace>();
  detail::buildRows(*problem_, *workspace_);
  precomputeSeconds_ = secondsSince(start);
}

GaussNewtonPlanarizer::~GaussNewtonPlanarizer() = default;

Info GaussNewtonPlanarizer::solve(Positions& vertices) {
  const auto start = SteadyClock::now();
  const detail::Problem& problem = *problem_;
  detail::GaussNewtonWorkspace& ws = *workspace_;
  Positions Y = detail::startingPoint(problem, vertices);
  Info info;
  detail::Monitor monitor(problem, *backend_, settings_.tolerance);
  bool converged = monitor.record(Y, info);
  double merit = detail::linearize(problem, Y, ws);
  // Fraction of the way back to the input each step aims for (the minimizer of
  // mu |dx|^2 + w |x + dx - x_input|^2 before the constraints are imposed).
  const double pullBack = settings_.closeness / (settings_.closeness + settings_.damping);
  // Softening of the linearized constraints (Levenberg-Marquardt on the dual system):
  // tiny, so that the step satisfies them; raised after a rejected step.
  constexpr double minimumSoftening = 1e-9;
  double softening = minimumSoftening;
  bool pullBackActive = true;
  int rejectedInARow = 0;
  Positions candidate, corrected;
  std::vector<Eigen::Matrix<double, 4, 3>> jacobianAtStep;
  while (!converged && info.iterations < settings_.maxIterations) {
    const compute::LinearSolveInfo solve =
        detail::computeStep(problem, Y, pullBackActive ? pullBack : 0.0, softening, *backend_, ws);
    ++info.iterations;
    info.linearResidual = std::max(info.linearResidual, solve.relativeResidual);
    if (!ws.step.allFinite()) {
      throwNumerical("planarize: Gauss-Newton step became non-finite at iteration " + std::to_string(info.iterations));
    }
    if (settings_.correctorSteps > 0) jacobianAtStep = ws.jacobian;
    // Backtracking on the merit sum c_j^2 (a step that lands within the tolerance is
    // always taken). The linearization at the accepted candidate is the next iteration's.
    bool accepted = false;
    double stepLength = 1.0;
    for (int halving = 0; halving <= 5 && !accepted; ++halving, stepLength *= 0.5) {
      candidate = Y + stepLength * ws.step;
      const double candidateMerit = detail::linearize(problem, candidate, ws);
      if (candidateMerit <= merit || monitor.wouldConverge(candidate)) {
        accepted = true;
        merit = candidateMerit;
      }
    }
    if (accepted && settings_.correctorSteps > 0 && !monitor.wouldConverge(candidate)) {
      // Corrector steps with this iteration's factor: the nonlinear part of the constraints
      // left by the step, removed at the cost of back-substitutions.
      Eigen::VectorXd residualNow = ws.residual;
      for (int c = 0; c < settings_.correctorSteps; ++c) {
        detail::correctorStep(problem, jacobianAtStep, residualNow, ws);
        corrected = candidate + ws.step;
        const double correctedMerit = detail::linearize(problem, corrected, ws);
        if (!(correctedMerit < merit)) break;
        ++info.correctorSteps;
        candidate.swap(corrected);
        merit = correctedMerit;
        residualNow = ws.residual;
      }
      // Leave the linearization of the accepted candidate in the workspace.
      detail::linearize(problem, candidate, ws);
    }
    if (accepted) {
      const double change = stepLength * ws.step.cwiseAbs().maxCoeff();
      Y.swap(candidate);
      softening = std::max(minimumSoftening, softening * 0.1);
      pullBackActive = true;
      rejectedInARow = 0;
      converged = monitor.record(Y, info);
      if (!converged && change < 1e-12) {
        info.status = Status::Stalled;
        break;
      }
    } else {
      // No decrease along the step: retry from Y with the pure Gauss-Newton projection
      // (no pull towards the input, a descent direction for the merit) and more softening.
      softening = std::min(1.0, softening * 10.0);
      pullBackActive = false;
      ++info.rejectedSteps;
      detail::linearize(problem, Y, ws);
      converged = monitor.record(Y, info);
      if (++rejectedInARow > 8) {
        info.status = Status::Stalled;
        break;
      }
    }
  }
  detail::finishSolve(problem, Y, converged, precomputeSeconds_ + secondsSince(start), info, vertices);
  return info;
}

}  // namespace plano::planarize
