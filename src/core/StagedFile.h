#pragma once
// The pieces of an atomic write: the new content goes to a temporary file next to its
// target, complete and on disk (fsync), and only then is it renamed over the target, so
// that a reader, a crash or a failure midway never sees half a file. One file
// (writeFileAtomically, mesh/MeshIO.h) or several renamed together (the plano tool's
// outputs of one run) are written with it.
#include <filesystem>
#include <functional>
#include <string>

namespace plano {

class StagedFile {
 public:
  /// Create the temporary file ".NAME.tmpPID-RANDOM" next to `target` (a path a symbolic
  /// link does not redirect: the caller resolves links). `shown` names the file in
  /// messages. Throws Error(BadInput) when it cannot be created.
  StagedFile(std::filesystem::path target, std::string shown);
  /// Removes the temporary file unless commit() renamed it, and the kept old file.
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  /// Write all of `content`, in pieces of 16 MiB with `between` called before each (may be
  /// empty; it may throw, e.g. plano::Interrupted), then flush it to disk and close it.
  /// Throws Error(BadInput) when a write fails.
  void write(const std::string& content, const std::function<void()>& between = {});
  /// Rename the written file over the target. Throws Error(BadInput) when it cannot.
  void commit();

  /// Before commit(): keep the target's current file under a second name (a hard link
  /// ".NAME.oldPID-RANDOM"), so that restorePrevious() can put it back. On a file system
  /// without hard links it is not kept, and restorePrevious() leaves the new file.
  void keepPrevious();
  /// After commit(), undo it: the kept file renamed back over the target, or the target
  /// removed where there was none before. Best effort, without throwing: it runs while
  /// another failure is being reported.
  void restorePrevious();

 private:
  std::filesystem::path target_;
  std::string shown_;
  std::filesystem::path temporary_;  ///< Empty once renamed.
  int fd_ = -1;                      ///< Open until write() closes it.
  std::filesystem::path previous_;   ///< The kept link to the old file (keepPrevious), or empty.
  bool kept_ = false;                ///< keepPrevious() succeeded.
  bool committed_ = false;
};

}  // namespace plano
