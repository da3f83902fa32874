#include "subspace/FaceSpace.h"

#include "core/Error.h"

namespace plano::subspace {

FaceSpace parseFaceSpace(const std::string& text) {
  if (text == "affine") return FaceSpace::Affine;
  if (text == "parallel") return FaceSpace::Parallel;
  if (text == "vertical") return FaceSpace::Vertical;
  throwUsage("unknown face space '" + text + "' (expected affine, parallel or vertical)");
}

SpaceKind parseSpaceKind(const std::string& text) {
  if (text == "mixed") return SpaceKind::Mixed;
  if (text == "affine") return SpaceKind::Affine;
  if (text == "parallel") return SpaceKind::Parallel;
  if (text == "vertical") return SpaceKind::Vertical;
  throwUsage("unknown space '" + text + "' (expected affine, parallel, vertical or mixed)");
}

const char* toString(FaceSpace space) {
  switch (space) {
    case FaceSpace::Affine: return "affine";
    case FaceSpace::Parallel: return "parallel";
    case FaceSpace::Vertical: return "vertical";
  }
  return "?";
}

const char* toString(SpaceKind kind) {
  switch (kind) {
    case SpaceKind::Affine: return "affine";
    case SpaceKind::Parallel: return "parallel";
    case SpaceKind::Vertical: return "vertical";
    case SpaceKind::Mixed: return "mixed";
  }
  return "?";
}

std::vector<FaceSpace> uniformAssignment(SpaceKind kind, Index faceCount) {
  FaceSpace space = FaceSpace::Affine;
  switch (kind) {
    case SpaceKind::Affine: space = FaceSpace::Affine; break;
    case SpaceKind::Parallel: space = FaceSpace::Parallel; break;
    case SpaceKind::Vertical: space = FaceSpace::Vertical; break;
    case SpaceKind::Mixed: throwUsage("a mixed space needs a per-face assignment (--faces-file)");
  }
  return std::vector<FaceSpace>(static_cast<std::size_t>(faceCount), space);
}

Index faceEquationCount(FaceSpace space, Index degree) {
  switch (space) {
    case FaceSpace::Affine: return 3 * (degree - 3);
    case FaceSpace::Parallel: return degree - 1;
    case FaceSpace::Vertical: return 2 * (degree - 2);
  }
  return 0;
}

}  // namespace plano::subspace
