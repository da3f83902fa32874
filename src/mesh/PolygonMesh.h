#pragma once
// A polygon mesh as flat arrays that solvers and GPUs use directly: vertex positions
// (#V x 3, double, row-major so that the buffer is x0 y0 z0 x1 ...) and faces in CSR
// form (offsets + vertex indices). Faces of any degree >= 3; order is preserved from
// input to output.
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace plano {

using Index = std::int32_t;
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Faces in compressed-row form: face f has the vertices indices[offsets[f] .. offsets[f+1]).
class FaceList {
 public:
  FaceList() = default;
  /// Build from a list of polygons (each a list of vertex indices, in order).
  explicit FaceList(const std::vector<std::vector<Index>>& polygons);

  void addFace(std::span<const Index> vertices);
  void addFace(std::initializer_list<Index> vertices) { addFace(std::span<const Index>(vertices.begin(), vertices.size())); }
  void reserve(std::size_t faces, std::size_t corners);

  Index size() const { return static_cast<Index>(offsets_.size() - 1); }
  bool empty() const { return size() == 0; }
  Index degree(Index f) const { return offsets_[f + 1] - offsets_[f]; }
  std::span<const Index> operator[](Index f) const {
    return {indices_.data() + offsets_[f], static_cast<std::size_t>(degree(f))};
  }
  /// Total number of corners (sum of face degrees).
  Index cornerCount() const { return static_cast<Index>(indices_.size()); }
  Index maxDegree() const;

  const std::vector<Index>& offsets() const { return offsets_; }
  const std::vector<Index>& indices() const { return indices_; }

  bool operator==(const FaceList& other) const = default;

 private:
  std::vector<Index> offsets_{0};
  std::vector<Index> indices_;
};

/// Geometry and connectivity of a polygon mesh. Derived topology (edges, boundary
/// loops, adjacency) lives in MeshTopology, built once from the faces.
struct PolygonMesh {
  Positions vertices;  ///< #V x 3
  FaceList faces;

  Index vertexCount() const { return static_cast<Index>(vertices.rows()); }
  Index faceCount() const { return faces.size(); }
};

/// Length of the bounding-box diagonal (0 for an empty mesh).
double boundingBoxDiagonal(const Positions& vertices);

/// The largest distance a vertex moved from `before` to `after` (same #V; 0 for none): the
/// local/global loops' displacement stopping test.
double maxVertexDistance(const Positions& before, const Positions& after);

}  // namespace plano
