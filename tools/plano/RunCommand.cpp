#include "plano/RunCommand.h"

#include <signal.h>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/ParallelFor.h"
#include "plano/Report.h"

namespace plano::cli {
namespace {

extern "C" void onInterruptSignal(int) { requestCancellation(); }

/// The failure report, unless the command wrote its own (more detailed) one since
/// `reportsBefore` reports had been written.
void writeFailureReport(const CommandRun& command, std::size_t reportsBefore, const std::string& status,
                        const std::string& reason, std::ostream& err) {
  const std::string reportPath = command.paths.report();
  if (reportPath.empty() || reportsWritten() != reportsBefore) return;
  try {
    writeReport(reportPath, failureReport(command.name, status, reason));
  } catch (const Error& e) {
    err << "plano: could not write the report: " << e.what() << std::endl;
  }
}

int runOnce(const CommandRun& command, const GlobalOptions& options) { return command.run(options); }

}  // namespace

int runCommand(const CommandRun& command, GlobalOptions options, std::ostream& err) {
  const std::size_t reportsBefore = reportsWritten();
  try {
    try {
      checkCommandPaths(command.paths);
      setCpuThreads(options.threads);
      cpuThreads();  // a malformed PLANO_THREADS is an error before any work, not in the middle of it
      return runOnce(command, options);
    } catch (const Error& e) {
      // With auto, a device error can only come from a Vulkan backend (the CPU one has no device).
      if (e.kind() != ErrorKind::Device || options.backend != "auto") throw;
      err << "warning: the Vulkan device failed (" << e.what() << "); running again on the CPU backend" << std::endl;
      options.backend = "cpu";
      return runOnce(command, options);
    }
  } catch (const Error& e) {
    err << "plano: " << toString(e.kind()) << ": " << e.what() << std::endl;
    if (e.kind() != ErrorKind::Usage) writeFailureReport(command, reportsBefore, failureStatus(e.kind()), e.what(), err);
    return exitCode(e.kind());
  } catch (const Interrupted& e) {
    err << "plano: interrupted: " << e.what() << "; no output written" << std::endl;
    writeFailureReport(command, reportsBefore, "interrupted", e.what(), err);
    return kInterruptedExitCode;
  }
}

void installInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = onInterruptSignal;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: reads and writes in progress complete; SA_RESETHAND: a second signal kills.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

}  // namespace plano::cli
