#pragma once
// The one place where a parsed command is run and its errors become exit codes, so that
// every command handles device failures, numerical failures and interruption alike.
#include <ostream>
#include <string>

#include "plano/Command.h"
#include "plano/OutputGuard.h"

namespace plano::cli {

struct CommandRun {
  std::string name;        ///< Sub-command name, for the failure report.
  RunFunction run;
  /// The files it reads and writes (--report among them): checked before it runs
  /// (checkCommandPaths), a usage error when they clash.
  CommandPaths paths;
};

/// Run the command. With --backend auto, a device failure (the Vulkan device broke
/// mid-run) is followed by a second run on the CPU backend, with a warning on `err`: auto
/// promises a result whenever the CPU can give one. Every plano::Error becomes
/// "plano: KIND: message" on `err`, a failure report when --report was given and the
/// command wrote none, and the kind's exit code (130 for an interrupted run).
int runCommand(const CommandRun& command, GlobalOptions options, std::ostream& err);

/// Install SIGINT/SIGTERM handlers that request cancellation (core/Cancellation.h) so that
/// the run stops at the next solver iteration instead of dying mid-write. A second signal
/// kills the process as usual.
void installInterruptHandlers();

}  // namespace plano::cli
