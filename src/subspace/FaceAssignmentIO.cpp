#include "subspace/FaceAssignmentIO.h"

#include <fstream>
#include <sstream>

#include "core/Error.h"

namespace plano::subspace {

std::vector<FaceSpace> readFaceAssignment(const std::filesystem::path& path, Index faceCount) {
  std::ifstream in(path);
  if (!in) throwBadInput("cannot open face assignment file " + path.string());
  std::vector<FaceSpace> spaces;
  std::string line;
  for (int lineNumber = 1; std::getline(in, line); ++lineNumber) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string word;
    while (words >> word) {
      if (word == "a" || word == "affine") {
        spaces.push_back(FaceSpace::Affine);
      } else if (word == "p" || word == "parallel") {
        spaces.push_back(FaceSpace::Parallel);
      } else if (word == "v" || word == "vertical") {
        spaces.push_back(FaceSpace::Vertical);
      } else {
        throwBadInput(path.string() + ":" + std::to_string(lineNumber) + ": unknown face space '" + word +
                      "' (expected affine, parallel or vertical)");
      }
    }
  }
  if (static_cast<Index>(spaces.size()) != faceCount) {
    throwBadInput(path.string() + ": " + std::to_string(spaces.size()) + " face spaces for a mesh of " +
                  std::to_string(faceCount) + " faces");
  }
  return spaces;
}

std::vector<FaceSpace> requestedAssignment(const std::string& space, const std::string& facesFile, Index faceCount) {
  const SpaceKind kind = parseSpaceKind(space);
  if (kind == SpaceKind::Mixed) {
    if (facesFile.empty()) throwUsage("--space mixed needs --faces-file");
    return readFaceAssignment(facesFile, faceCount);
  }
  if (!facesFile.empty()) throwUsage("--faces-file is only used with --space mixed");
  return uniformAssignment(kind, faceCount);
}

}  // namespace plano::subspace
