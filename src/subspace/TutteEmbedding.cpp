#include "subspace/TutteEmbedding.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "subspace/SubspaceTopology.h"

namespace plano::subspace {
namespace {

double signedArea(const Positions& X, std::span<const Index> face) {
  double area = 0.0;
  for (std::size_t i = 0; i < face.size(); ++i) {
    const Index a = face[i], b = face[(i + 1) % face.size()];
    area += X(a, 0) * X(b, 1) - X(b, 0) * X(a, 1);
  }
  return 0.5 * area;
}

}  // namespace

Positions tutteEmbedding(compute::Backend& backend, const FaceList& faces, Index vertexCount,
                         const TutteSettings& settings, TutteInfo* info) {
  const SubspaceTopology t = computeTopology(faces, vertexCount);
  if (t.components != 1 || t.boundaryLoopCount() != 1 || t.genus != 0) {
    throwBadInput("Tutte embedding needs a disk: the mesh has " + std::to_string(t.components) + " component(s), " +
                  std::to_string(t.boundaryLoopCount()) + " boundary loop(s) and genus " + std::to_string(t.genus));
  }
  const auto& loop = t.boundaryLoops.front();
  Positions X = Positions::Zero(vertexCount, 3);
  std::vector<Index> slot(static_cast<std::size_t>(vertexCount), -1);
  const Index nb = static_cast<Index>(loop.size());
  for (Index i = 0; i < nb; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / nb;
    X(loop[i], 0) = settings.radius * std::cos(angle);
    X(loop[i], 1) = settings.radius * std::sin(angle);
    slot[loop[i]] = -2;  // Pinned.
  }
  Index ni = 0;
  for (Index v = 0; v < vertexCount; ++v)
    if (slot[v] == -1) slot[v] = ni++;
  // L_II x_I = -L_IB x_B with the uniform graph Laplacian.
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixX2d rhs = Eigen::MatrixX2d::Zero(ni, 2);
  for (const auto& e : t.edges) {
    for (int side = 0; side < 2; ++side) {
      const Index a = e[side], b = e[1 - side];
      if (slot[a] < 0) continue;
      triplets.emplace_back(slot[a], slot[a], 1.0);
      if (slot[b] >= 0) {
        triplets.emplace_back(slot[a], slot[b], -1.0);
      } else {
        rhs.row(slot[a]) += X.row(b).head<2>();
      }
    }
  }
  if (ni > 0) {
    compute::SparseMatrix L(ni, ni);
    L.setFromTriplets(triplets.begin(), triplets.end());
    L.makeCompressed();
    // An iterative backend's error in x is its residual times L's condition number, which
    // grows with the mesh: a tolerance near rounding keeps the embedding the direct solve's.
    compute::LinearSolverSettings solverSettings;
    solverSettings.relativeTolerance = 1e-13;
    solverSettings.maxIterations = static_cast<int>(std::max<Index>(10000, 4 * ni));
    Eigen::MatrixXd interior = Eigen::MatrixXd::Zero(ni, 2);
    const compute::LinearSolveInfo solve = backend.createSpdSolver(L, solverSettings)->solve(rhs, interior);
    if (!solve.converged || !interior.allFinite()) {
      std::ostringstream message;
      message << "Tutte embedding: the solve failed (" << solve.iterations << " iterations, relative residual "
              << solve.relativeResidual << ")";
      throwNumerical(message.str());
    }
    for (Index v = 0; v < vertexCount; ++v)
      if (slot[v] >= 0) X.row(v).head<2>() = interior.row(slot[v]);
  }
  // Orient so that the faces are counter-clockwise (the boundary loop's direction decides).
  double total = 0.0;
  for (Index f = 0; f < faces.size(); ++f) total += signedArea(X, faces[f]);
  if (total < 0.0) X.col(1) = -X.col(1);
  TutteInfo local;
  local.boundaryVertices = nb;
  local.interiorVertices = ni;
  for (Index f = 0; f < faces.size(); ++f) local.flippedFaces += signedArea(X, faces[f]) <= 0.0 ? 1 : 0;
  if (info) *info = local;
  return X;
}

Positions tutteEmbedding(const FaceList& faces, Index vertexCount, const TutteSettings& settings, TutteInfo* info) {
  compute::CpuBackend cpu;
  return tutteEmbedding(cpu, faces, vertexCount, settings, info);
}

}  // namespace plano::subspace
