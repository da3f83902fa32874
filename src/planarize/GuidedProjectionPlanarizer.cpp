#include "planarize/GuidedProjectionPlanarizer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "compute/SparsePattern.h"
#include "core/Error.h"
#include "core/Timing.h"
#include "planarize/Monitor.h"
#include "planarize/Problem.h"

namespace plano::planarize {
namespace detail {

/// Private caches of GuidedProjectionPlanarizer: the reduced system's pattern, the slots every
/// face writes into, and the per-face plane unknowns with what back-substitution needs.
struct GuidedProjectionWorkspace {
  compute::SparseMatrix system;     ///< 3 #free square, pattern fixed, values per iteration.
  std::vector<int> faceSlotOffset;  ///< Per constrained face: start of its (3k)^2 slots.
  std::vector<int> faceSlots;       ///< Value index of (corner a, corner b, row r, col c), -1 if fixed.
  std::vector<int> diagonalSlots;   ///< 3 per free vertex.
  Eigen::MatrixXd rhs;              ///< 3 #free x 1.
  Eigen::MatrixXd solution;         ///< 3 #free x 1; warm start for iterative backends.
  std::vector<Eigen::Vector4d> planes;  ///< (n, d) per constrained face.
  std::vector<Eigen::Matrix4d> blockInverse;
  std::vector<Eigen::Vector4d> blockRhs;
};

namespace {

void buildPattern(const Problem& problem, GuidedProjectionWorkspace& ws) {
  const FaceList& faces = *problem.faces;
  const Index n = 3 * problem.freeCount;
  std::vector<Eigen::Triplet<double>> triplets;
  std::size_t total = 0;
  for (Index f : problem.constrainedFaces) total += 9 * static_cast<std::size_t>(faces.degree(f) * faces.degree(f));
  triplets.reserve(total + static_cast<std::size_t>(n));
  for (Index row = 0; row < n; ++row) triplets.emplace_back(row, row, 0.0);
  for (Index f : problem.constrainedFaces) {
    for (Index i : faces[f]) {
      const Index fi = problem.freeIndex[i];
      if (fi < 0) continue;
      for (Index j : faces[f]) {
        const Index fj = problem.freeIndex[j];
        if (fj < 0) continue;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * fi + r, 3 * fj + c, 0.0);
      }
    }
  }
  ws.system.resize(n, n);
  ws.system.setFromTriplets(triplets.begin(), triplets.end());
  ws.system.makeCompressed();
  ws.diagonalSlots.resize(static_cast<std::size_t>(n));
  for (Index row = 0; row < n; ++row) ws.diagonalSlots[row] = compute::storedEntryIndex(ws.system, row, row);
  ws.faceSlotOffset.resize(problem.constrainedFaces.size());
  ws.faceSlots.clear();
  ws.faceSlots.reserve(total);
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    ws.faceSlotOffset[c] = static_cast<int>(ws.faceSlots.size());
    for (Index i : face) {
      for (Index j : face) {
        const Index fi = problem.freeIndex[i];
        const Index fj = problem.freeIndex[j];
        for (int r = 0; r < 3; ++r)
          for (int col = 0; col < 3; ++col)
            ws.faceSlots.push_back(fi < 0 || fj < 0 ? -1 : compute::storedEntryIndex(ws.system, 3 * fi + r, 3 * fj + col));
      }
    }
  }
}

/// Penalty energy of Y: squared corner distances to each face's best-fit plane over h_f^2,
/// plus closeness. The merit function of the step acceptance.
double penaltyEnergy(const Problem& problem, const Positions& Y, double closeness) {
  const FaceList& faces = *problem.faces;
  double energy = 0.0;
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    const FacePlane plane = bestFitPlane(Y, face);
    double sum = 0.0;
    for (Index i : face) {
      const double distance = plane.normal.dot(Y.row(i).transpose() - plane.centroid);
      sum += distance * distance;
    }
    energy += sum / (problem.faceSize[c] * problem.faceSize[c]);
  }
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    if (problem.freeIndex[v] >= 0) energy += closeness * (Y.row(v) - problem.input.row(v)).squaredNorm();
  }
  return energy;
}

void fitPlanes(const Problem& problem, const Positions& Y, GuidedProjectionWorkspace& ws) {
  ws.planes.resize(problem.constrainedFaces.size());
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const FacePlane plane = bestFitPlane(Y, (*problem.faces)[problem.constrainedFaces[c]]);
    ws.planes[c] << plane.normal, plane.normal.dot(plane.centroid);
  }
}

/// Fill the reduced system and right-hand side for the linearization at (Y, planes).
/// Corner a of face f has the linearized residual n^k.x_a + (n_f, d_f).(x_a^k, -1) - n^k.x_a^k.
void assemble(const Problem& problem, const Positions& Y, double closeness, double damping,
              GuidedProjectionWorkspace& ws) {
  const FaceList& faces = *problem.faces;
  constexpr double normalizationWeight = 1.0;
  double* values = ws.system.valuePtr();
  std::fill(values, values + ws.system.nonZeros(), 0.0);
  ws.rhs.setZero(3 * problem.freeCount, 1);
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    const Index fv = problem.freeIndex[v];
    if (fv < 0) continue;
    for (int r = 0; r < 3; ++r) {
      values[ws.diagonalSlots[3 * fv + r]] += closeness + damping;
      ws.rhs(3 * fv + r, 0) += closeness * problem.input(v, r) + damping * Y(v, r);
    }
  }
  ws.blockInverse.resize(problem.constrainedFaces.size());
  ws.blockRhs.resize(problem.constrainedFaces.size());
  Eigen::Matrix<double, 4, Eigen::Dynamic> A;
  Eigen::VectorXd b, q;
  Eigen::MatrixXd K;
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    const Index k = static_cast<Index>(face.size());
    const double s = 1.0 / (problem.faceSize[c] * problem.faceSize[c]);
    const Eigen::Vector4d& plane = ws.planes[c];
    const Eigen::Vector3d normal = plane.head<3>();
    A.resize(4, k);
    b.resize(k);
    for (Index a = 0; a < k; ++a) {
      A.col(a) << Y.row(face[a]).transpose(), -1.0;
      b[a] = normal.dot(Y.row(face[a]).transpose());
    }
    // Plane block B and its right-hand side: corner rows, linearized |n| = 1, damping.
    const Eigen::Vector4d n0(normal.x(), normal.y(), normal.z(), 0.0);
    Eigen::Matrix4d B = s * (A * A.transpose()) + normalizationWeight * (n0 * n0.transpose());
    B.diagonal().array() += damping;
    const Eigen::Vector4d g =
        s * (A * b) + normalizationWeight * 0.5 * (normal.squaredNorm() + 1.0) * n0 + damping * plane;
    const Eigen::Matrix4d Binv = B.inverse();
    ws.blockInverse[c] = Binv;
    ws.blockRhs[c] = g;
    // Schur complement of the plane block: corner block (a, b) is K_ab n n^T with
    // K = s I - s^2 A^T B^-1 A; the right-hand side of corner a is n (s b_a - s a_a^T B^-1 g).
    K = -(s * s) * (A.transpose() * Binv * A);
    K.diagonal().array() += s;
    q = s * b - s * (A.transpose() * (Binv * g));
    const Eigen::Matrix3d nnT = normal * normal.transpose();
    const int* slots = ws.faceSlots.data() + ws.faceSlotOffset[c];
    for (Index a = 0; a < k; ++a) {
      const Index fa = problem.freeIndex[face[a]];
      if (fa < 0) continue;
      Eigen::Vector3d rhs = q[a] * normal;
      for (Index bb = 0; bb < k; ++bb) {
        if (problem.freeIndex[face[bb]] < 0) {
          // A fixed corner's term moves to the right-hand side.
          rhs -= K(a, bb) * normal.dot(Y.row(face[bb]).transpose()) * normal;
          continue;
        }
        const int* block = slots + (a * k + bb) * 9;
        for (int r = 0; r < 3; ++r)
          for (int col = 0; col < 3; ++col) values[block[3 * r + col]] += K(a, bb) * nnT(r, col);
      }
      ws.rhs.block<3, 1>(3 * fa, 0) += rhs;
    }
  }
}

/// New planes from the solved positions (back-substitution of the eliminated block),
/// rescaled to unit normals: the linearization point of the next iteration.
void updatePlanes(const Problem& problem, const Positions& oldY, const Positions& newY, GuidedProjectionWorkspace& ws) {
  const FaceList& faces = *problem.faces;
  for (std::size_t c = 0; c < problem.constrainedFaces.size(); ++c) {
    const auto face = faces[problem.constrainedFaces[c]];
    const double s = 1.0 / (problem.faceSize[c] * problem.faceSize[c]);
    const Eigen::Vector3d normal = ws.planes[c].head<3>();
    Eigen::Vector4d t = ws.blockRhs[c];
    for (Index i : face) {
      Eigen::Vector4d a;
      a << oldY.row(i).transpose(), -1.0;
      t -= s * normal.dot(newY.row(i).transpose()) * a;
    }
    Eigen::Vector4d plane = ws.blockInverse[c] * t;
    const double length = plane.head<3>().norm();
    if (!(length > 1e-8) || !plane.allFinite()) {
      const FacePlane fit = bestFitPlane(newY, face);
      plane << fit.normal, fit.normal.dot(fit.centroid);
    } else {
      plane /= length;
    }
    ws.planes[c] = plane;
  }
}

}  // namespace
}  // namespace detail

GuidedProjectionPlanarizer::GuidedProjectionPlanarizer(const FaceList& faces, const Positions& input, const Settings& settings,
                                             compute::Backend& backend)
    : settings_(settings), backend_(&backend) {
  const auto start = SteadyClock::now();
  problem_ = std::make_unique<detail::Problem>(detail::makeProblem(faces, input, settings));
  workspace_ = std::make_unique<detail::GuidedProjectionWorkspace>();
  detail::buildPattern(*problem_, *workspace_);
  precomputeSeconds_ = secondsSince(start);
}

GuidedProjectionPlanarizer::~GuidedProjectionPlanarizer() = default;

Info GuidedProjectionPlanarizer::solve(Positions& vertices) {
  const auto start = SteadyClock::now();
  const detail::Problem& problem = *problem_;
  detail::GuidedProjectionWorkspace& ws = *workspace_;
  Positions Y = detail::startingPoint(problem, vertices);
  Info info;
  detail::Monitor monitor(problem, *backend_, settings_.tolerance);
  bool converged = monitor.record(Y, info);
  detail::fitPlanes(problem, Y, ws);
  double energy = detail::penaltyEnergy(problem, Y, settings_.closeness);
  double damping = settings_.damping;
  Positions candidate;
  int rejectedInARow = 0;
  while (!converged && info.iterations < settings_.maxIterations) {
    detail::assemble(problem, Y, settings_.closeness, damping, ws);
    ws.solution.resize(3 * problem.freeCount, 1);
    for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
      const Index fv = problem.freeIndex[v];
      if (fv >= 0) ws.solution.block<3, 1>(3 * fv, 0) = Y.row(v).transpose();
    }
    // The matrix changes every iteration (it depends on the normals): a fresh solver per
    // step; a direct backend factors it, an iterative one warm-starts from Y.
    const auto solver = backend_->createSpdSolver(ws.system, compute::LinearSolverSettings{});
    const compute::LinearSolveInfo solve = solver->solve(ws.rhs, ws.solution);
    ++info.iterations;
    info.linearResidual = std::max(info.linearResidual, solve.relativeResidual);
    if (!ws.solution.allFinite()) {
      throwNumerical("planarize: guided projection step became non-finite at iteration " + std::to_string(info.iterations));
    }
    candidate = Y;
    for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
      const Index fv = problem.freeIndex[v];
      if (fv >= 0) candidate.row(v) = ws.solution.block<3, 1>(3 * fv, 0).transpose();
    }
    const double candidateEnergy = detail::penaltyEnergy(problem, candidate, settings_.closeness);
    if (candidateEnergy <= energy * (1.0 + 1e-12)) {
      detail::updatePlanes(problem, Y, candidate, ws);
      const double change = (candidate - Y).cwiseAbs().maxCoeff();
      Y.swap(candidate);
      energy = candidateEnergy;
      damping = std::max(settings_.damping, damping * 0.1);
      rejectedInARow = 0;
      converged = monitor.record(Y, info);
      if (!converged && change < 1e-12) {
        info.status = Status::Stalled;
        break;
      }
    } else {
      // Levenberg-Marquardt: a step that raises the energy is retried, shorter.
      damping *= 10.0;
      ++info.rejectedSteps;
      converged = monitor.record(Y, info);
      if (++rejectedInARow > 12) {
        info.status = Status::Stalled;
        break;
      }
    }
  }
  detail::finishSolve(problem, Y, converged, precomputeSeconds_ + secondsSince(start), info, vertices);
  return info;
}

}  // namespace plano::planarize
