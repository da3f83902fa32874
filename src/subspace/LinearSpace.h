#pragma once
// A linear space of polyhedral meshes in one object: its source mesh, the constraint
// matrix B and an orthonormal basis N of null(B) (linear-spaces paper, §2 and §4).
// Built once; eigenshapes, shapes, projections and deformations take it by reference.
#include <span>

#include "subspace/ConstraintMatrix.h"
#include "subspace/DegreesOfFreedom.h"
#include "subspace/NullSpaceBasis.h"

namespace plano::subspace {

struct LinearSpaceSettings {
  ConstraintSettings constraints;
  BasisSettings basis;
};

struct LinearSpace {
  PolygonMesh source;
  ConstraintMatrix B;
  SubspaceBasis N;
  BasisInfo basisInfo;
  DegreesOfFreedom dof;
};

/// Build B for `source` with per-face types `spaces` and its null-space basis.
LinearSpace buildLinearSpace(const PolygonMesh& source, std::span<const FaceSpace> spaces,
                             const LinearSpaceSettings& settings = {});

}  // namespace plano::subspace
