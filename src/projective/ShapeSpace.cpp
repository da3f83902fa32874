#include "projective/ShapeSpace.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "core/Error.h"

namespace plano::projective {
namespace {

/// Below this |weight| a corner image is treated as a point at infinity.
constexpr double kMinimumWeight = 1e-12;

}  // namespace

ShapeSpace::ShapeSpace(const PolygonMesh& base) : base_(base), faces_(base.faces) {
  const Index vertexCount = base.vertexCount();
  for (Index v = 0; v < vertexCount; ++v) {
    if (!base.vertices.row(v).allFinite()) {
      throwBadInput("shape space: vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  for (Index f = 0; f < faces_.size(); ++f) {
    const auto face = faces_[f];
    if (face.size() < 3) {
      throwBadInput("shape space: face " + std::to_string(f) + " has " + std::to_string(face.size()) +
                    " corners (at least 3 needed)");
    }
    for (std::size_t i = 0; i < face.size(); ++i) {
      if (face[i] < 0 || face[i] >= vertexCount) {
        throwBadInput("shape space: face " + std::to_string(f) + " refers to vertex " + std::to_string(face[i]) +
                      ", out of range (" + std::to_string(vertexCount) + " vertices)");
      }
      for (std::size_t j = 0; j < i; ++j) {
        if (face[j] == face[i]) {
          throwBadInput("shape space: face " + std::to_string(f) + " lists vertex " + std::to_string(face[i]) +
                        " twice");
        }
      }
    }
  }

  normalization_ = Normalization::fromBoundingBox(base.vertices);
  basePositions_ = normalization_.toNormalized(base.vertices);

  const Index corners = faces_.cornerCount();
  cornerFace_.resize(corners);
  for (Index f = 0; f < faces_.size(); ++f) {
    for (Index c = faces_.offsets()[f]; c < faces_.offsets()[f + 1]; ++c) cornerFace_[c] = f;
  }
  vertexCornerOffsets_.assign(vertexCount + 1, 0);
  for (Index v : faces_.indices()) ++vertexCornerOffsets_[v + 1];
  for (Index v = 0; v < vertexCount; ++v) vertexCornerOffsets_[v + 1] += vertexCornerOffsets_[v];
  cornersOfVertex_.resize(corners);
  std::vector<Index> fill(vertexCornerOffsets_.begin(), vertexCornerOffsets_.end() - 1);
  for (Index c = 0; c < corners; ++c) cornersOfVertex_[fill[faces_.indices()[c]]++] = c;

  // Faces sharing an (undirected) edge, each pair once.
  std::map<std::pair<Index, Index>, std::vector<Index>> edgeFaces;
  for (Index f = 0; f < faces_.size(); ++f) {
    const auto face = faces_[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const Index a = face[i];
      const Index b = face[(i + 1) % face.size()];
      edgeFaces[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  }
  for (const auto& [edge, incident] : edgeFaces) {
    for (std::size_t i = 0; i < incident.size(); ++i) {
      for (std::size_t j = i + 1; j < incident.size(); ++j) {
        if (incident[i] != incident[j]) {
          adjacentFaces_.emplace_back(std::min(incident[i], incident[j]), std::max(incident[i], incident[j]));
        }
      }
    }
  }
  std::sort(adjacentFaces_.begin(), adjacentFaces_.end());
  adjacentFaces_.erase(std::unique(adjacentFaces_.begin(), adjacentFaces_.end()), adjacentFaces_.end());
}

FaceMaps ShapeSpace::identityMaps() const {
  FaceMaps maps;
  maps.maps.assign(faceCount(), Eigen::Matrix4d::Identity());
  maps.reciprocalScales.assign(cornerCount(), 1.0);
  return maps;
}

std::vector<double> ShapeSpace::inducedReciprocalScales(const std::vector<Eigen::Matrix4d>& maps) const {
  if (static_cast<Index>(maps.size()) != faceCount()) {
    throwUsage("shape space: " + std::to_string(maps.size()) + " maps given for " + std::to_string(faceCount()) +
               " faces");
  }
  std::vector<double> scales(cornerCount());
  for (Index c = 0; c < cornerCount(); ++c) {
    const Index v = faces_.indices()[c];
    scales[c] = homogeneous(basePositions_.row(v)).dot(maps[cornerFace_[c]].col(3));
  }
  return scales;
}

Positions ShapeSpace::normalizedPositions(const std::vector<Eigen::Matrix4d>& maps) const {
  if (static_cast<Index>(maps.size()) != faceCount()) {
    throwUsage("shape space: " + std::to_string(maps.size()) + " maps given for " + std::to_string(faceCount()) +
               " faces");
  }
  Positions result = basePositions_;
  for (Index v = 0; v < vertexCount(); ++v) {
    const Index begin = vertexCornerOffsets_[v];
    const Index end = vertexCornerOffsets_[v + 1];
    if (begin == end) continue;
    const Eigen::RowVector4d p = homogeneous(basePositions_.row(v));
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (Index k = begin; k < end; ++k) {
      const Index f = cornerFace_[cornersOfVertex_[k]];
      const Eigen::RowVector4d image = p * maps[f];
      if (!(std::abs(image[3]) > kMinimumWeight) || !image.allFinite()) {
        throwNumerical("shape space: the map of face " + std::to_string(f) + " sends vertex " + std::to_string(v) +
                       " to infinity (homogeneous weight " + std::to_string(image[3]) + ")");
      }
      sum += image.head<3>() / image[3];
    }
    result.row(v) = sum / static_cast<double>(end - begin);
  }
  return result;
}

double ShapeSpace::maxCornerDisagreement(const std::vector<Eigen::Matrix4d>& maps) const {
  const Positions mean = normalizedPositions(maps);
  double worst = 0.0;
  for (Index v = 0; v < vertexCount(); ++v) {
    const Eigen::RowVector4d p = homogeneous(basePositions_.row(v));
    for (Index k = vertexCornerOffsets_[v]; k < vertexCornerOffsets_[v + 1]; ++k) {
      const Eigen::RowVector4d image = p * maps[cornerFace_[cornersOfVertex_[k]]];
      worst = std::max(worst, (image.head<3>() / image[3] - mean.row(v)).norm());
    }
  }
  return worst;
}

}  // namespace plano::projective
