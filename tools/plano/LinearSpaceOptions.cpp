#include "plano/LinearSpaceOptions.h"

#include "subspace/FaceAssignmentIO.h"

namespace plano::cli {

std::vector<subspace::FaceSpace> LinearSpaceOptions::assignment(Index faceCount) const {
  return subspace::requestedAssignment(space, facesFile, faceCount);
}

subspace::LinearSpaceSettings LinearSpaceOptions::settings() const {
  subspace::LinearSpaceSettings settings;
  settings.constraints.up = Eigen::Vector3d(up[0], up[1], up[2]);
  return settings;
}

void addUpOption(CLI::App& app, std::vector<double>& up) {
  app.add_option("--up", up, "Up vector of the vertical faces, X,Y,Z")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str();
}

void addLinearSpaceOptions(CLI::App& app, LinearSpaceOptions& options, const std::string& spaceHelp) {
  auto* space = app.add_option("--space", options.space, spaceHelp)
                    ->check(CLI::IsMember({"affine", "parallel", "vertical", "mixed"}));
  if (!options.space.empty()) space->capture_default_str();
  app.add_option("--faces-file", options.facesFile,
                 "With --space mixed: per-face types, one word per face in face order (affine | parallel | "
                 "vertical, or a | p | v)");
  addUpOption(app, options.up);
}

}  // namespace plano::cli
