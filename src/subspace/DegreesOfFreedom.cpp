#include "subspace/DegreesOfFreedom.h"

namespace plano::subspace {

Index subspaceLowerBound(const FaceList& faces, Index vertexCount, std::span<const FaceSpace> spaces) {
  Index equations = 0;
  for (Index f = 0; f < faces.size(); ++f) equations += faceEquationCount(spaces[f], faces.degree(f));
  return 3 * vertexCount - equations;
}

DegreesOfFreedom degreesOfFreedom(Index dimension, const FaceList& faces, Index vertexCount,
                                  std::span<const FaceSpace> spaces) {
  DegreesOfFreedom dof;
  dof.dimension = dimension;
  dof.lowerBound = subspaceLowerBound(faces, vertexCount, spaces);
  dof.freeVertices = dimension / 3.0;
  dof.lowerBoundFreeVertices = dof.lowerBound / 3.0;
  return dof;
}

}  // namespace plano::subspace
