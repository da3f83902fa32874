#include "plano/LinearSpaceOptions.h"

#include <chrono>
#include <cstdio>

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

subspace::LinearSpace buildSpaceWithProgress(const GlobalOptions& global, const std::string& command,
                                             const PolygonMesh& mesh, const std::string& spaceName,
                                             std::span<const subspace::FaceSpace> spaces,
                                             const subspace::LinearSpaceSettings& settings) {
  progress(global, command + ": building the " + spaceName + " space of " + std::to_string(mesh.faceCount()) +
                       " faces (constraint matrix, null-space basis) ...");
  const auto start = std::chrono::steady_clock::now();
  subspace::LinearSpace space = subspace::buildLinearSpace(mesh, spaces, settings);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  char time[32];
  std::snprintf(time, sizeof time, "%.3g s", seconds);
  progress(global, command + ": " + spaceName + " space: dimension " + std::to_string(space.dof.dimension) + " (" +
                       (space.basisInfo.method == subspace::BasisMethod::DenseSvd ? "dense SVD" : "sparse QR") +
                       " of " + std::to_string(space.basisInfo.unknowns) + " unknowns, " + time + ")");
  warnIfFacesAreNotPlanar(command, space);
  return space;
}

}  // namespace plano::cli
