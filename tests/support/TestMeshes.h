#pragma once
// Shared helpers for tests: mesh families, the shared architectural meshes (skipped when
// ../shared/data is absent), random perturbations and matrix comparisons.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <random>
#include <string>

#include "mesh/PolygonMesh.h"

namespace plano::test {

/// Folder of the real architectural meshes next to the checkout (../shared/data), if present.
std::optional<std::filesystem::path> sharedDataDir();

/// Path of a shared mesh, or GTEST_SKIP()s from the calling test when it is missing.
#define PLANO_REQUIRE_SHARED_MESH(var, name)                                                      \
  auto var##_dir = ::plano::test::sharedDataDir();                                               \
  if (!var##_dir || !std::filesystem::exists(*var##_dir / (name))) {                             \
    GTEST_SKIP() << "shared mesh " << (name) << " not found (../shared/data is absent)";         \
  }                                                                                               \
  const std::filesystem::path var = *var##_dir / (name)

/// Add uniform noise of the given amplitude to every coordinate (deterministic seed).
Positions perturbed(const Positions& vertices, double amplitude, unsigned seed = 7);

/// Largest absolute entry of a - b.
double maxAbsDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
/// max |a - b| / max |b|: a difference relative to b's scale.
double relativeMaxDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

/// A rows x columns matrix of standard normal entries (deterministic seed).
Eigen::MatrixXd gaussianMatrix(Index rows, Index columns, unsigned seed);

/// A temporary folder removed at destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// Run the plano tool with arguments; returns the exit code, captures stdout and stderr.
struct ToolResult {
  int exitCode = -1;
  std::string out;
  std::string err;
};
ToolResult runTool(const std::string& arguments);
/// `path` in double quotes: one word of runTool's arguments even with spaces in it.
std::string quotedPath(const std::filesystem::path& path);

}  // namespace plano::test
