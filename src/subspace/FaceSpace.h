#pragma once
// The relationship a face keeps with its source polygon inside a linear space of
// polyhedral meshes (linear-spaces paper, §2, Theorem 1 and "Generating subspaces").
#include <span>
#include <string>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::subspace {

/// Per-face relationship type.
enum class FaceSpace : unsigned char {
  Affine,    ///< Type 1: the face is an affine image of its source.
  Parallel,  ///< Type 2 with N_X = N_Y: the face keeps its normal, free offset.
  Vertical,  ///< Type 2 with N_X = up: the face turns about its horizontal line u x n.
};

/// Whole-mesh choice: one type for every face, or a per-face assignment (mixed).
enum class SpaceKind { Affine, Parallel, Vertical, Mixed };

/// "affine" | "parallel" | "vertical" (and "mixed" for parseSpaceKind); throws Error(Usage).
FaceSpace parseFaceSpace(const std::string& text);
SpaceKind parseSpaceKind(const std::string& text);
const char* toString(FaceSpace space);
const char* toString(SpaceKind kind);

/// The same type for every face of a mesh of `faceCount` faces (kind must not be Mixed).
std::vector<FaceSpace> uniformAssignment(SpaceKind kind, Index faceCount);

/// Number of independent linear equations a k-gon of the given type contributes to B
/// after the per-face rank reduction of §4: affine 3(k-3), parallel k-1, vertical 2(k-2).
Index faceEquationCount(FaceSpace space, Index degree);

}  // namespace plano::subspace
