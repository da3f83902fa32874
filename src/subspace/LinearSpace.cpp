#include "subspace/LinearSpace.h"

namespace plano::subspace {

LinearSpace buildLinearSpace(const PolygonMesh& source, std::span<const FaceSpace> spaces,
                             const LinearSpaceSettings& settings) {
  LinearSpace space;
  space.source = source;
  space.B = buildConstraintMatrix(source, spaces, settings.constraints);
  space.N = computeNullSpaceBasis(space.B, settings.basis, &space.basisInfo);
  space.dof = degreesOfFreedom(space.N.dimension(), source.faces, source.vertexCount(), space.B.effective);
  return space;
}

}  // namespace plano::subspace
