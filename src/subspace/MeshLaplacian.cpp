#include "subspace/MeshLaplacian.h"

#include "subspace/SubspaceTopology.h"

namespace plano::subspace {

compute::SparseMatrix uniformLaplacian(const FaceList& faces, Index vertexCount) {
  const SubspaceTopology topology = computeTopology(faces, vertexCount);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(topology.edges.size() * 4);
  for (const auto& e : topology.edges) {
    triplets.emplace_back(e[0], e[1], -1.0);
    triplets.emplace_back(e[1], e[0], -1.0);
    triplets.emplace_back(e[0], e[0], 1.0);
    triplets.emplace_back(e[1], e[1], 1.0);
  }
  compute::SparseMatrix L(vertexCount, vertexCount);
  L.setFromTriplets(triplets.begin(), triplets.end());
  return L;
}

}  // namespace plano::subspace
