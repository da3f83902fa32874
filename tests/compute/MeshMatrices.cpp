#include "compute/MeshMatrices.h"

#include <random>
#include <vector>

namespace plano::test {

compute::SparseMatrix laplacianLikeSpd(const PolygonMesh& mesh, double shift, Index pinEvery) {
  std::vector<Eigen::Triplet<double, int>> entries;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    const auto face = mesh.faces[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const Index a = face[i], b = face[(i + 1) % face.size()];
      // Every interior edge is seen from both faces: weight 1/2 per side.
      entries.emplace_back(a, b, -0.5);
      entries.emplace_back(b, a, -0.5);
      entries.emplace_back(a, a, 0.5);
      entries.emplace_back(b, b, 0.5);
    }
  }
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    entries.emplace_back(v, v, shift + (v % pinEvery == 0 ? 100.0 : 0.0));
  }
  compute::SparseMatrix A(mesh.vertexCount(), mesh.vertexCount());
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

compute::SparseMatrix randomSparse(Index rows, Index cols, int perRow, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> column(0, cols - 1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double, int>> entries;
  for (Index r = 0; r < rows; ++r) {
    for (int k = 0; k < perRow; ++k) entries.emplace_back(r, column(rng), value(rng));
  }
  compute::SparseMatrix A(rows, cols);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

}  // namespace plano::test
