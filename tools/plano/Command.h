#pragma once
// Sub-commands of the `plano` tool register themselves here, one file per command in
// tools/plano/commands/, so that adding a command touches no other file.
#include <CLI/CLI.hpp>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "compute/Admm.h"
#include "compute/Backend.h"
#include "subspace/LinearSpace.h"

namespace plano::cli {

/// Options every command shares (parsed before the sub-command runs).
struct GlobalOptions {
  std::string backend = "cpu";  ///< cpu | vulkan | auto
  bool quiet = false;           ///< No progress on stderr.
  int threads = 0;              ///< CPU threads of the per-face work (0: cpuThreads()'s default).
};

/// A command's run function: returns the exit code. Errors are thrown as plano::Error
/// and turned into messages and exit codes by main.
using RunFunction = std::function<int(const GlobalOptions&)>;

/// Sets up the sub-command's options on `app` and returns the function that runs it.
using SetupFunction = std::function<RunFunction(CLI::App& app)>;

struct CommandInfo {
  std::string name;
  std::string description;
  SetupFunction setup;
  int order = 100;  ///< Position in --help.
};

std::vector<CommandInfo>& commandRegistry();

/// Static registration helper: `static CommandRegistration reg{{"info", "...", setup}};`
struct CommandRegistration {
  explicit CommandRegistration(CommandInfo info) { commandRegistry().push_back(std::move(info)); }
};

/// Checks of numeric options whose messages say what is wrong in the user's terms
/// ("--tolerance: must be > 0 (got 0)", "must be finite (got inf)") rather than CLI11's
/// ranges up to the largest double written out in 300 digits.
CLI::Validator positiveNumber();     ///< Finite and > 0.
CLI::Validator nonNegativeNumber();  ///< Finite and >= 0.
/// Finite and within [low, high], or (low, high) when `open`.
CLI::Validator numberBetween(double low, double high, bool open = false);

/// Bound of the options that scale a displacement by the bounding-box diagonal (--amplitude,
/// --height): far beyond any useful edit, and far from coordinates no mesh file may hold.
constexpr double kMaxAmplitude = 100.0;

/// Create the backend the user asked for, printing a fallback warning on stderr.
std::unique_ptr<compute::Backend> makeBackend(const GlobalOptions& options);

/// For a command that computes on the CPU whatever the backend (subspace, sparse shapes, the
/// dual alone; `reason` says why): a warning on stderr, even with --quiet, when --backend
/// vulkan asked for the device, so that nobody takes its results or timings for the
/// device's. Returns the backend name for the report.
std::string warnComputesOnCpu(const GlobalOptions& options, const std::string& command, const std::string& reason);

/// For a linear-space command whose heavy products run on the backend (`deviceWork`, e.g.
/// "the reduced operator": the d x d matrix N^T S N of eigenshapes and fundamental shapes,
/// compute::Backend::reducedOperator) while the linear space's basis and the small dense
/// problem run on the CPU: the backend asked for, and with a device backend a line on stderr
/// (unless --quiet) saying which part runs where.
std::unique_ptr<compute::Backend> makeLinearSpaceBackend(const GlobalOptions& options, const std::string& command,
                                                         const std::string& deviceWork);

/// Above this largest relative face non-planarity (third over first singular value of a face's
/// centred corners) a mesh is not planar to its file's rounding (real planar-quad meshes
/// stored with 6 digits reach ~1e-4), and its linear spaces are only approximate.
constexpr double kLinearSpaceNonPlanarityWarning = 1e-3;

/// For a linear-space command on a mesh whose faces are not planar (kLinearSpaceNonPlanarityWarning):
/// a warning on stderr, even with --quiet, that the space is built from the faces' best-fit
/// planes with a rank tolerance grown to match, so that its shapes are polyhedral only to
/// about that tolerance, and that the mesh should be planarized first.
void warnIfFacesAreNotPlanar(const std::string& command, const subspace::LinearSpace& space);

/// Progress line on stderr unless --quiet.
void progress(const GlobalOptions& options, const std::string& message);

/// For AdmmSettings::onCheck: unless --quiet, a line on stderr with the ADMM's iteration and
/// residuals at most every `interval` (a global step on a large mesh can run minutes between
/// its command's own per-iteration lines); empty with --quiet.
std::function<void(const compute::AdmmCheck&)> admmHeartbeat(
    const GlobalOptions& options, std::chrono::steady_clock::duration interval = std::chrono::seconds(10));

}  // namespace plano::cli
