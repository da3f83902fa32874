#include "subspace/LinearSpace.h"

namespace plano::subspace {

LinearSpace buildLinearSpace(const PolygonMesh& source, std::span<const FaceSpace> spaces,
                             const LinearSpaceSettings& settings) {
  LinearSpace space;
  space.source = source;
  space.B = buildConstraintMatrix(source, spaces, settings.constraints);
  // A basis whose lower bound alone cannot fit is refused before the sparse QR, which
  // takes seconds to minutes on such meshes and memory of its own.
  const Index bound = subspaceLowerBound(source.faces, source.vertexCount(), space.B.effective);
  requireBasisMemory(static_cast<Index>(space.B.matrix.cols()), space.B.separable ? bound / 3 : bound,
                     /*atLeast=*/true, settings.basis.memoryLimitBytes);
  space.N = computeNullSpaceBasis(space.B, settings.basis, &space.basisInfo);
  space.dof = degreesOfFreedom(space.N.dimension(), source.faces, source.vertexCount(), space.B.effective);
  return space;
}

}  // namespace plano::subspace
