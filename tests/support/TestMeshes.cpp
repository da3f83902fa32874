#include "support/TestMeshes.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>

namespace plano::test {

std::optional<std::filesystem::path> sharedDataDir() {
  if (const char* env = std::getenv("PLANO_SHARED_DATA")) return std::filesystem::path(env);
  const std::filesystem::path candidate = std::filesystem::path(PLANO_SOURCE_DIR) / ".." / "shared" / "data";
  if (std::filesystem::is_directory(candidate)) return candidate;
  return std::nullopt;
}

Positions perturbed(const Positions& vertices, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  Positions result = vertices;
  for (Eigen::Index i = 0; i < result.size(); ++i) result.data()[i] += noise(rng);
  return result;
}

double maxAbsDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

double relativeMaxDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return maxAbsDifference(a, b) / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
}

Eigen::MatrixXd gaussianMatrix(Index rows, Index columns, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> value;
  Eigen::MatrixXd M(rows, columns);
  for (Index i = 0; i < M.size(); ++i) M.data()[i] = value(rng);
  return M;
}

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "plano-test-XXXXXX").string();
  path_ = mkdtemp(pattern.data());
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string quotedPath(const std::filesystem::path& path) {
  std::string quoted = "\"";
  quoted += path.string();
  quoted += '"';
  return quoted;
}

ToolResult runTool(const std::string& arguments) {
  TempDir dir;
  const auto out = dir / "stdout";
  const auto err = dir / "stderr";
  const std::string command =
      std::string(PLANO_TOOL_PATH) + " " + arguments + " >" + out.string() + " 2>" + err.string() + " </dev/null";
  const int status = std::system(command.c_str());
  ToolResult result;
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  result.out = slurp(out);
  result.err = slurp(err);
  return result;
}

}  // namespace plano::test
