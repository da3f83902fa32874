#pragma once
// Coarsening of positional constraints and the choice of the deformation level for
// multi-resolution editing (projective-maps paper, §6.2, §6.5).
//
// The user constrains vertices of the finest mesh M_n. On a coarser level M_k:
//  - a coarse vertex is fixed iff its fine counterpart is fixed (for an approximating
//    scheme it is held at its coarse position, §6.5);
//  - a handle (fine vertex p moved to q) constrains the projective maps of the ancestors
//    on M_k of the fine faces around p: (p, 1) A_f must be proportional to (q, 1). The maps
//    act on all of P^3, so p need not lie on the coarse face.
// A map has one free point of the ambient space left besides its face plane, so each
// coarse face can satisfy one such constraint exactly. The deformation level is the
// coarsest level on which no face is constrained by more than one handle, or by a handle
// and a fixed point; the finest level always qualifies (its handles are plain vertices).
#include <string>
#include <vector>

#include "mesh/Constraints.h"
#include "projective/MultiresHierarchy.h"

namespace plano::projective {

/// (point, 1) A_face proportional to (target, 1): a handle attached to a coarse face's map.
struct MapPointConstraint {
  Index face = 0;        ///< Face of the coarse level.
  Index handle = 0;      ///< Index into PositionalConstraints::handles.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< p: the handle's position on the finest level.
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< q: where the user moved it.
};

/// The user's constraints seen from one level of the hierarchy.
struct CoarseConstraints {
  int level = 0;
  std::vector<Index> fixed;                  ///< Fixed vertices of the level (sorted).
  std::vector<MapPointConstraint> handles;   ///< One entry per (handle, attached face).
};

/// Coarsen fine constraints to `level`. In: the hierarchy, the finest positions
/// (#V_n x 3), the constraints on the finest level. Throws Error(BadInput) for a
/// constrained vertex that does not exist on the finest level, Error(Usage) for a level
/// outside the hierarchy or positions of the wrong size.
CoarseConstraints coarsenConstraints(const SubdivisionHierarchy& hierarchy, const Positions& finest,
                                     const PositionalConstraints& constraints, int level);

/// Why a level was rejected by the rule of §6.2 (empty when it qualifies).
struct LevelCheck {
  int level = 0;
  bool admissible = true;
  Index conflictFace = -1;  ///< First face of the level that breaks the rule.
  std::string reason;       ///< e.g. "face 3 carries handles 0 and 2".
};

/// The paper's rule applied to every level, coarsest first; returns the checks in level
/// order 0..n, the last always admissible.
std::vector<LevelCheck> checkDeformationLevels(const SubdivisionHierarchy& hierarchy,
                                               const PositionalConstraints& constraints);

/// The coarsest admissible level (§6.2, §6.4 step 2).
int chooseDeformationLevel(const SubdivisionHierarchy& hierarchy, const PositionalConstraints& constraints);

}  // namespace plano::projective
