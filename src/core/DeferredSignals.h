#pragma once
// Deferral of SIGINT and SIGTERM around work that must not stop halfway (an atomic
// write's rename, several outputs renamed together). The plano tool's first Ctrl-C only
// sets the cancellation flag (core/Cancellation.h), but a second one kills the process:
// blocked, it cannot leave a temporary file behind or some targets replaced and others
// not. POSIX threads only; the mask is the calling thread's.
#include <pthread.h>
#include <signal.h>

namespace plano {

/// Blocks SIGINT and SIGTERM in the calling thread while it lives.
class DeferredSignals {
 public:
  DeferredSignals() {
    sigemptyset(&signals_);
    sigaddset(&signals_, SIGINT);
    sigaddset(&signals_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals_, &previous_);
  }
  ~DeferredSignals() { pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  DeferredSignals(const DeferredSignals&) = delete;
  DeferredSignals& operator=(const DeferredSignals&) = delete;

  /// Lets a pending signal in (its handler sets the flag) between two pieces of work.
  void poll() {
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
    pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
  }

 private:
  sigset_t signals_;
  sigset_t previous_;
};

}  // namespace plano
