#include "mesh/PolygonMesh.h"

#include <algorithm>

namespace plano {

FaceList::FaceList(const std::vector<std::vector<Index>>& polygons) {
  std::size_t corners = 0;
  for (const auto& p : polygons) corners += p.size();
  reserve(polygons.size(), corners);
  for (const auto& p : polygons) addFace(std::span<const Index>(p));
}

void FaceList::addFace(std::span<const Index> vertices) {
  indices_.insert(indices_.end(), vertices.begin(), vertices.end());
  offsets_.push_back(static_cast<Index>(indices_.size()));
}

void FaceList::reserve(std::size_t faces, std::size_t corners) {
  offsets_.reserve(faces + 1);
  indices_.reserve(corners);
}

Index FaceList::maxDegree() const {
  Index best = 0;
  for (Index f = 0; f < size(); ++f) best = std::max(best, degree(f));
  return best;
}

double boundingBoxDiagonal(const Positions& vertices) {
  if (vertices.rows() == 0) return 0.0;
  return (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
}

double maxVertexDistance(const Positions& before, const Positions& after) {
  return before.rows() == 0 ? 0.0 : (after - before).rowwise().norm().maxCoeff();
}

}  // namespace plano
