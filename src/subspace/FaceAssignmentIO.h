#pragma once
// Per-face space assignments of mixed spaces, as a text file: one word per face
// (affine | parallel | vertical, or a | p | v), in face order, separated by white space;
// '#' starts a comment that runs to the end of the line.
#include <filesystem>
#include <string>
#include <vector>

#include "subspace/FaceSpace.h"

namespace plano::subspace {

/// Read an assignment for a mesh of `faceCount` faces. Throws Error(BadInput) naming the
/// file, line and word for an unknown type or a count mismatch.
std::vector<FaceSpace> readFaceAssignment(const std::filesystem::path& path, Index faceCount);

/// The assignment a command asks for: `space` is affine | parallel | vertical (every face)
/// or mixed (read from `facesFile`, which must then be given). Throws Error(Usage).
std::vector<FaceSpace> requestedAssignment(const std::string& space, const std::string& facesFile, Index faceCount);

}  // namespace plano::subspace
