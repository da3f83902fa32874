// plano: command-line tool for polyhedral meshes. Each sub-command lives in
// tools/plano/commands/ and registers itself (Command.h).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "core/Error.h"
#include "plano/Command.h"
#include "plano/OutputGuard.h"
#include "plano/RunCommand.h"

namespace plano::cli {

std::vector<CommandInfo>& commandRegistry() {
  static std::vector<CommandInfo> registry;
  return registry;
}

std::unique_ptr<compute::Backend> makeBackend(const GlobalOptions& options) {
  std::string warnings;
  auto backend = compute::createBackend(compute::parseBackendChoice(options.backend), &warnings);
  if (!warnings.empty()) std::cerr << warnings;
  return backend;
}

std::string warnComputesOnCpu(const GlobalOptions& options, const std::string& command, const std::string& reason) {
  if (options.backend == "vulkan") {
    std::cerr << "warning: plano " << command << " computes on the CPU: " << reason
              << " (--backend vulkan "
                 "applies to subdivide, planarize, prescribe, interpolate and deform, to the reduced operators "
                 "of explore, dual --primal and shapes --kind fundamental, and to embed)"
              << std::endl;
  }
  return "cpu";
}

void warnIfFacesAreNotPlanar(const std::string& command, const subspace::LinearSpace& space) {
  if (!(space.B.maxNonPlanarity > kLinearSpaceNonPlanarityWarning)) return;
  std::cerr << "warning: plano " << command << ": the mesh's faces are not planar (largest relative non-planarity "
            << space.B.maxNonPlanarity << "): its linear space is built from the faces' best-fit planes with rank "
            << "tolerance " << space.basisInfo.rankTolerance << ", and its shapes are polyhedral only to about that; "
            << "planarize the mesh first (plano planarize)" << std::endl;
}

std::unique_ptr<compute::Backend> makeLinearSpaceBackend(const GlobalOptions& options, const std::string& command,
                                                         const std::string& deviceWork) {
  auto backend = makeBackend(options);
  if (backend->kind() != compute::BackendKind::Cpu && !options.quiet) {
    std::cerr << "plano " << command << ": " << deviceWork << " on " << backend->name()
              << "; the linear space's basis and the small dense problem on the CPU" << std::endl;
  }
  return backend;
}

namespace {

/// A validator of the number an option's text holds: `problem` returns what is wrong with a
/// finite value, or "" when nothing is. Text that is no number is left to CLI11's conversion.
CLI::Validator numberCheck(std::function<std::string(double)> problem, const std::string& description) {
  return CLI::Validator(
      [problem](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return {};
        if (!std::isfinite(value)) return "must be finite (got " + text + ")";
        const std::string why = problem(value);
        return why.empty() ? why : why + " (got " + text + ")";
      },
      description);
}

/// A bound as the user would write it: 2, 0.5, 1e+06.
std::string shortNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

CLI::Validator positiveNumber() {
  return numberCheck([](double value) { return value > 0.0 ? "" : "must be > 0"; }, "POSITIVE");
}

CLI::Validator nonNegativeNumber() {
  return numberCheck([](double value) { return value >= 0.0 ? "" : "must be >= 0"; }, "NONNEGATIVE");
}

CLI::Validator numberBetween(double low, double high, bool open) {
  const std::string range = (open ? "(" : "[") + shortNumber(low) + ", " + shortNumber(high) + (open ? ")" : "]");
  return numberCheck(
      [=](double value) -> std::string {
        const bool inside = open ? (value > low && value < high) : (value >= low && value <= high);
        return inside ? "" : "must be in " + range;
      },
      "in " + range);
}

void progress(const GlobalOptions& options, const std::string& message) {
  if (!options.quiet) std::cerr << message << std::endl;
}

std::function<void(const compute::AdmmCheck&)> admmHeartbeat(const GlobalOptions& options,
                                                              std::chrono::steady_clock::duration interval) {
  if (options.quiet) return {};
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [last, interval](const compute::AdmmCheck& check) {
    const auto now = std::chrono::steady_clock::now();
    if (now - *last < interval) return;
    *last = now;
    std::ostringstream line;
    line << std::setprecision(3) << "  ADMM iteration " << check.iterations << ": primal residual "
         << check.primalResidual << " (tolerance " << check.primalTolerance << "), dual residual "
         << check.dualResidual << " (tolerance " << check.dualTolerance << "), rho " << check.rho << ", "
         << check.linearIterations << " inner solve iterations";
    std::cerr << line.str() << std::endl;
  };
}

namespace {

/// Every floating-point option (CLI11's FLOAT values, lists included) must be finite: a NaN
/// passes every "> 0" check, and a NaN or Inf weight, tolerance, amplitude or coordinate
/// would otherwise run (or fail as a numerical error) instead of being a usage error.
void requireFiniteFloatOptions(CLI::App& app) {
  const CLI::Validator finite = numberCheck([](double) { return std::string(); }, "");
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(finite);
  }
}

/// The files a parsed command reads and writes, by the names every command gives its
/// options (positional "mesh", "topology", "a", "b"; --base, --constraints, --fixed,
/// --faces-file read; --output, --primal, --report written, in that order).
CommandPaths commandPaths(const CLI::App& command) {
  const auto given = [&](const std::string& name) -> std::string {
    const CLI::Option* option = command.get_option_no_throw(name);
    return option != nullptr && option->count() > 0 ? option->as<std::string>() : std::string();
  };
  CommandPaths paths;
  for (const char* name : {"mesh", "topology", "a", "b", "--base", "--constraints", "--fixed", "--faces-file"}) {
    if (const std::string path = given(name); !path.empty()) paths.inputs.push_back(path);
  }
  for (const char* name : {"--output", "--primal", "--report"}) {
    const CLI::Option* option = command.get_option_no_throw(name);
    paths.outputs.push_back({name, given(name), option != nullptr && option->count() > 0});
  }
  const CLI::Option* inPlace = command.get_option_no_throw("--in-place");
  paths.inPlaceOption = inPlace != nullptr;
  paths.inPlace = inPlace != nullptr && inPlace->count() > 0;
  return paths;
}

}  // namespace
}  // namespace plano::cli

int main(int argc, char** argv) {
  using namespace plano::cli;
  // First, so that a signal arriving at any time after start-up stops the run cleanly.
  installInterruptHandlers();
  CLI::App app{"plano: modelling polyhedral meshes (planar faces) with projective maps and linear spaces"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "plano 0.1.0");
  GlobalOptions options;
  app.add_option("--backend", options.backend, "Compute backend: cpu, vulkan or auto (Vulkan on a real GPU, else CPU)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}))
      ->capture_default_str();
  app.add_flag("-q,--quiet", options.quiet, "No progress messages on stderr");
  app.add_option("--threads", options.threads,
                 "CPU threads for the per-face work (0: the PLANO_THREADS environment variable, else every core)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();

  auto& registry = commandRegistry();
  std::stable_sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  RunFunction selected;
  std::vector<std::pair<CLI::App*, RunFunction>> commands;
  for (const auto& info : registry) {
    CLI::App* sub = app.add_subcommand(info.name, info.description);
    // Global options are accepted after the sub-command name too: `plano info --backend cpu m.obj`.
    sub->fallthrough();
    commands.emplace_back(sub, info.setup(*sub));
    requireFiniteFloatOptions(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : plano::exitCode(plano::ErrorKind::Usage);
  }

  try {
    for (auto& [sub, run] : commands) {
      if (!sub->parsed()) continue;
      const CommandRun command{sub->get_name(), run, commandPaths(*sub)};
      return runCommand(command, options, std::cerr);
    }
    return plano::exitCode(plano::ErrorKind::Usage);
  } catch (const std::bad_alloc&) {
    std::cerr << "plano: out of memory" << std::endl;
    return plano::exitCode(plano::ErrorKind::Numerical);
  } catch (const std::exception& e) {
    std::cerr << "plano: internal error: " << e.what() << std::endl;
    return 1;
  }
}
