#pragma once
// The options that choose a linear space of polyhedral meshes (linear-spaces paper, §2):
// --space, --faces-file and --up. `subspace`, `explore`, `shapes` and `deform --space`
// register them here, so that each takes the same three with the same meaning.
#include <CLI/CLI.hpp>
#include <string>
#include <utility>
#include <vector>

#include "plano/Command.h"
#include "subspace/FaceSpace.h"
#include "subspace/LinearSpace.h"

namespace plano::cli {

struct LinearSpaceOptions {
  /// `defaultSpace` is --space's value when it is not given ("": none, as in deform).
  explicit LinearSpaceOptions(std::string defaultSpace = "affine") : space(std::move(defaultSpace)) {}

  std::string space;             ///< affine | parallel | vertical | mixed; empty: not given (deform).
  std::string facesFile;         ///< Per-face types of a mixed space (subspace/FaceAssignmentIO.h).
  std::vector<double> up{0.0, 0.0, 1.0};  ///< The vertical direction of vertical faces.

  /// The per-face types asked for: `space` on every face, or --faces-file's for mixed.
  /// Throws Error(Usage) for mixed without a file, Error(BadInput) for a wrong file.
  std::vector<subspace::FaceSpace> assignment(Index faceCount) const;
  /// Linear-space settings with the up vector (checked where B is built).
  subspace::LinearSpaceSettings settings() const;
};

/// Register --up alone (`dual`, whose --space has fewer choices).
void addUpOption(CLI::App& app, std::vector<double>& up);

/// Register --space (described by `spaceHelp`, its default shown when `options.space` has
/// one), --faces-file and --up on `app`, writing into `options`.
void addLinearSpaceOptions(CLI::App& app, LinearSpaceOptions& options,
                           const std::string& spaceHelp = "affine | parallel | vertical | mixed");

/// Build the linear space `spaces` (the per-face types of the space called `spaceName`) of
/// `mesh` for `command`: a progress line before the null-space basis, which takes a minute
/// on a 100k-face mesh, and one with its dimension and time after (unless --quiet); the
/// warning of warnIfFacesAreNotPlanar.
subspace::LinearSpace buildSpaceWithProgress(const GlobalOptions& global, const std::string& command,
                                             const PolygonMesh& mesh, const std::string& spaceName,
                                             std::span<const subspace::FaceSpace> spaces,
                                             const subspace::LinearSpaceSettings& settings);

}  // namespace plano::cli
