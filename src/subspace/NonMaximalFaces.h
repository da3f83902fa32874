#pragma once
// Faces whose assigned space is not maximal (linear-spaces paper, §2 after Theorem 3 and
// Fig. 4): the constraints the other faces impose may confine a face to a smaller space
// that is also contained in another type's space (the cube in the parallel space can only
// stretch its faces: every motion of a face is also an affine image). Reassigning such a
// face to the other type gives a space that contains the old one, often strictly.
#include <vector>

#include "subspace/LinearSpace.h"

namespace plano::subspace {

struct NonMaximalFace {
  Index face = 0;
  FaceSpace assigned = FaceSpace::Affine;     ///< Effective type now.
  FaceSpace containedIn = FaceSpace::Affine;  ///< Another type whose constraints every member already meets.
};

/// Faces f (non-triangles) such that every member of `space` restricted to f also meets
/// the constraints of another type: max |B'_f N_f| <= tolerance. Affine is tried first,
/// then vertical, then parallel (the order that frees the most, §4 "Selecting the Right Space").
std::vector<NonMaximalFace> findNonMaximalFaces(const LinearSpace& space, const ConstraintSettings& settings = {},
                                                double tolerance = 1e-8);

struct ReassignmentSettings {
  LinearSpaceSettings space;
  Index maxRounds = 4;
  double tolerance = 1e-8;
};

struct ReassignmentInfo {
  Index rounds = 0;             ///< Rounds whose reassignment was kept.
  Index reassignedFaces = 0;
  Index dimensionBefore = 0;
  Index dimensionAfter = 0;
};

/// Repeatedly reassign the non-maximal faces (all at once per round) and keep a round
/// only when the dimension grows. Returns the final per-face types.
std::vector<FaceSpace> reassignNonMaximalFaces(const PolygonMesh& mesh, std::vector<FaceSpace> spaces,
                                               const ReassignmentSettings& settings = {},
                                               ReassignmentInfo* info = nullptr);

}  // namespace plano::subspace
