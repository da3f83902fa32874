#include "planarize/Problem.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace plano::planarize::detail {

double meanDiagonal(const Positions& vertices, std::span<const Index> face) {
  const std::size_t k = face.size();
  const std::size_t runs = (k == 4) ? 2 : k;
  double sum = 0.0;
  for (std::size_t i = 0; i < runs; ++i) sum += (vertices.row(face[(i + 2) % k]) - vertices.row(face[i])).norm();
  return sum / static_cast<double>(runs);
}

FacePlane bestFitPlane(const Positions& vertices, std::span<const Index> face) {
  FacePlane plane;
  for (Index v : face) plane.centroid += vertices.row(v).transpose();
  plane.centroid /= static_cast<double>(face.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (Index v : face) {
    const Eigen::Vector3d p = vertices.row(v).transpose() - plane.centroid;
    covariance.noalias() += p * p.transpose();
  }
  // The closed-form 3x3 solver is several times faster than the iterative one and
  // accurate enough for a normal (its eigenvalues are what is less precise).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(covariance);
  plane.normal = eig.eigenvectors().col(0).normalized();
  return plane;
}

Problem makeProblem(const FaceList& faces, const Positions& input, const Settings& settings) {
  if (!(settings.closeness >= 0.0) || !std::isfinite(settings.closeness)) {
    throwUsage("planarize: closeness weight must be finite and >= 0 (got " + std::to_string(settings.closeness) + ")");
  }
  if (!(settings.tolerance >= 0.0)) throwUsage("planarize: tolerance must be >= 0 percent");
  if (settings.maxIterations < 0) throwUsage("planarize: max iterations must be >= 0");
  if (settings.andersonDepth < 1) throwUsage("planarize: Anderson depth must be >= 1");
  if (!(settings.damping > 0.0)) throwUsage("planarize: damping must be > 0");
  if (settings.correctorSteps < 0) throwUsage("planarize: corrector steps must be >= 0");

  const Index vertexCount = static_cast<Index>(input.rows());
  for (Index v = 0; v < vertexCount; ++v) {
    if (!input.row(v).allFinite()) throwBadInput("planarize: vertex " + std::to_string(v) + " has a non-finite coordinate");
  }
  Problem problem;
  problem.faces = &faces;
  problem.freeIndex.assign(static_cast<std::size_t>(vertexCount), 0);
  for (Index v : settings.fixed) {
    if (v < 0 || v >= vertexCount) {
      throwBadInput("planarize: fixed vertex " + std::to_string(v) + " is out of range (mesh has " +
                    std::to_string(vertexCount) + " vertices)");
    }
    if (problem.freeIndex[v] < 0) throwBadInput("planarize: fixed vertex " + std::to_string(v) + " is listed twice");
    problem.freeIndex[v] = -1;
  }
  for (Index v = 0; v < vertexCount; ++v) {
    if (problem.freeIndex[v] >= 0) problem.freeIndex[v] = problem.freeCount++;
  }
  // ShapeUp's global matrix is singular without an anchor (translations are free); the
  // Gauss-Newton methods are damped and need none.
  const bool needsAnchor = settings.method == Method::ShapeUp || settings.method == Method::Anderson;
  if (needsAnchor && settings.closeness == 0.0 && settings.fixed.empty()) {
    throwUsage(std::string("planarize: ") + toString(settings.method) +
               " with closeness 0 needs at least one fixed vertex (else the mesh may drift freely)");
  }

  problem.boundingBoxDiagonal = boundingBoxDiagonal(input);
  if (vertexCount > 0) problem.center = 0.5 * (input.colwise().minCoeff() + input.colwise().maxCoeff());
  double sizeSum = 0.0;
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    for (Index v : face) {
      if (v < 0 || v >= vertexCount) {
        throwBadInput("planarize: face " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
                      ", out of range");
      }
    }
    if (face.size() < 4) continue;
    const double size = meanDiagonal(input, face);
    // A face whose corners all coincide has planarity 0 by the measure and no plane.
    if (!(size > 0.0)) continue;
    problem.constrainedFaces.push_back(f);
    problem.faceSize.push_back(size);
    sizeSum += size;
  }
  if (!problem.constrainedFaces.empty()) {
    problem.scale = sizeSum / static_cast<double>(problem.constrainedFaces.size());
  } else if (problem.boundingBoxDiagonal > 0.0) {
    problem.scale = problem.boundingBoxDiagonal;
  }
  for (double& size : problem.faceSize) size /= problem.scale;
  problem.input = toNormalized(problem, input);
  problem.original = input;
  return problem;
}

Positions toOriginal(const Problem& problem, const Positions& normalized) {
  Positions result = (normalized * problem.scale).rowwise() + problem.center;
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    if (problem.freeIndex[v] < 0) result.row(v) = problem.original.row(v);
  }
  return result;
}

Positions toNormalized(const Problem& problem, const Positions& original) {
  Positions result = (original.rowwise() - problem.center) / problem.scale;
  return result;
}

Positions startingPoint(const Problem& problem, const Positions& vertices) {
  Positions start = toNormalized(problem, vertices);
  for (Index v = 0; v < static_cast<Index>(problem.freeIndex.size()); ++v) {
    if (problem.freeIndex[v] < 0) start.row(v) = problem.input.row(v);
  }
  return start;
}

void measureDisplacement(const Problem& problem, const Positions& normalized, Info& info) {
  info.maxDisplacement = 0.0;
  info.meanDisplacement = 0.0;
  const Index n = static_cast<Index>(normalized.rows());
  if (n == 0 || !(problem.boundingBoxDiagonal > 0.0)) return;
  double sum = 0.0;
  for (Index v = 0; v < n; ++v) {
    const double d = (normalized.row(v) - problem.input.row(v)).norm();
    sum += d;
    info.maxDisplacement = std::max(info.maxDisplacement, d);
  }
  const double factor = problem.scale / problem.boundingBoxDiagonal;
  info.maxDisplacement *= factor;
  info.meanDisplacement = sum / static_cast<double>(n) * factor;
}

void finishSolve(const Problem& problem, const Positions& normalized, bool converged, double seconds, Info& info,
                 Positions& vertices) {
  if (converged) info.status = Status::Converged;
  measureDisplacement(problem, normalized, info);
  vertices = toOriginal(problem, normalized);
  info.seconds = seconds;
}

}  // namespace plano::planarize::detail
