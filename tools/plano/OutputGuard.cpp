#include "plano/OutputGuard.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>

#include "core/Cancellation.h"
#include "core/DeferredSignals.h"
#include "core/Error.h"
#include "core/StagedFile.h"
#include "mesh/MeshIO.h"

namespace plano::cli {
namespace {

/// Canonical form of a path that may not exist yet: its existing folder canonicalized,
/// the remaining components appended.
std::filesystem::path canonicalForm(const std::string& path) {
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
  return ec ? std::filesystem::absolute(path).lexically_normal() : canonical;
}

/// Same file by device and inode: catches hard links, which paths alone cannot.
bool sameInode(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/// The folder a file is written into must exist and be writable (the atomic write creates
/// a temporary file there). `target` is where `path` resolves.
void checkOutputFolder(const std::string& path, const std::filesystem::path& target, const std::string& what) {
  const std::filesystem::path folder = std::filesystem::absolute(target).parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throwUsage(what + " " + path + ": the folder " + folder.string() + " does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throwUsage(what + " " + path + ": the folder " + folder.string() + " is not writable");
  }
}

/// The options whose files are meshes, in the format their extension names.
bool writesMesh(const std::string& option) { return option == "--output" || option == "--primal"; }

/// The same file, by path or by inode; empty paths never are.
bool sameFile(const std::string& a, const std::string& b) {
  return !a.empty() && !b.empty() && (canonicalForm(a) == canonicalForm(b) || sameInode(a, b));
}

}  // namespace

std::string CommandPaths::report() const {
  for (const WrittenFile& output : outputs) {
    if (output.option == "--report") return output.path;
  }
  return {};
}

void checkCommandPaths(const CommandPaths& paths) {
  for (std::size_t i = 0; i < paths.outputs.size(); ++i) {
    const auto& [option, path, given] = paths.outputs[i];
    if (path.empty()) {
      if (given) throwUsage(option + ": the path is empty");
      continue;
    }
    for (std::size_t k = 0; k < paths.inputs.size(); ++k) {
      const bool resultOverMesh = i == 0 && k == 0;
      if ((resultOverMesh && paths.inPlace) || !sameFile(paths.inputs[k], path)) continue;
      const bool inPlaceWouldDo = resultOverMesh && paths.inPlaceOption;
      throwUsage(option + " " + path + " is the input file " + paths.inputs[k] + ": refusing to overwrite it (" +
                 (inPlaceWouldDo ? "write elsewhere, or pass --in-place)" : "write elsewhere)"));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (sameFile(path, paths.outputs[j].path)) {
        throwUsage(option + " " + path + " is also the file of " + paths.outputs[j].option +
                   ": give them different files");
      }
    }
    if (writesMesh(option)) {
      try {
        meshFormatFromPath(path);
      } catch (const Error& e) {
        throwUsage(option + " " + e.what());
      }
    }
    const OutputTarget target = resolveOutput(path);
    if (target.stream) {
      if (::access(target.path.c_str(), W_OK) != 0) throwUsage(option + " " + path + ": not writable");
    } else {
      checkOutputFolder(path, target.path, option);
    }
  }
}

OutputTarget resolveOutput(const std::string& path) {
  // Links are followed by hand: the standard library's canonical forms do not follow a link
  // whose file does not exist yet, and writing through such a link creates that file.
  std::filesystem::path target = std::filesystem::absolute(path);
  struct stat info {};
  for (int links = 0; ::lstat(target.c_str(), &info) == 0 && S_ISLNK(info.st_mode); ++links) {
    if (links == 40) throwUsage(path + ": too many levels of symbolic links");
    std::error_code ec;
    const std::filesystem::path next = std::filesystem::read_symlink(target, ec);
    if (ec) throwUsage(path + ": cannot read the symbolic link " + target.string() + " (" + ec.message() + ")");
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  if (::lstat(target.c_str(), &info) != 0 || S_ISREG(info.st_mode)) return {target, false};
  if (S_ISFIFO(info.st_mode) || S_ISCHR(info.st_mode)) return {target, true};
  const char* kind = S_ISDIR(info.st_mode)    ? "a folder"
                     : S_ISSOCK(info.st_mode) ? "a socket"
                     : S_ISBLK(info.st_mode)  ? "a block device"
                                              : "not a regular file";
  throwUsage(path + (target == std::filesystem::absolute(path) ? "" : " (" + target.string() + ")") + " is " + kind +
             ": give a file to write");
}

namespace {

/// Write all of `content` to the stream `fd` (a FIFO or device); false with errno set when a
/// write fails.
bool writeAll(int fd, const std::string& content) {
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return true;
}

}  // namespace

void OutputFiles::add(std::string path, std::string content) { files_.push_back({std::move(path), std::move(content)}); }

void OutputFiles::commit() {
  std::vector<OutputTarget> targets;
  for (const File& file : files_) targets.push_back(resolveOutput(file.path));
  {
    DeferredSignals deferred;
    const auto between = [&] {
      if (!interruptible_) return;
      deferred.poll();
      if (cancellationRequested()) throw Interrupted("stopped during writing the results");
    };
    // Every regular file complete on disk before any is renamed; an exception removes the
    // temporary files written so far (StagedFile's destructor).
    std::vector<std::unique_ptr<StagedFile>> staged;
    for (std::size_t i = 0; i < files_.size(); ++i) {
      if (targets[i].stream) continue;
      staged.push_back(std::make_unique<StagedFile>(targets[i].path, files_[i].path));
      staged.back()->write(files_[i].content, between);
    }
    between();
    for (const auto& file : staged) file->keepPrevious();
    std::size_t renamed = 0;
    try {
      for (; renamed < staged.size(); ++renamed) {
        if (beforeRename_) beforeRename_(renamed);
        staged[renamed]->commit();
      }
    } catch (...) {
      for (std::size_t i = 0; i < renamed; ++i) staged[i]->restorePrevious();
      throw;
    }
  }
  // Streams last, with signals let in: opening a FIFO waits for its reader, and Ctrl-C must
  // still end a run that waits for one that never comes.
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (!targets[i].stream) continue;
    const int fd = ::open(targets[i].path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (fd < 0 || !writeAll(fd, files_[i].content)) {
      const std::string why = std::strerror(errno);
      if (fd >= 0) ::close(fd);
      throwBadInput(files_[i].path + ": write failed (" + why + ")");
    }
    ::close(fd);
  }
}

}  // namespace plano::cli
