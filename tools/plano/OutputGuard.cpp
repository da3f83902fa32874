#include "plano/OutputGuard.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "core/Error.h"

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
/// a temporary file there).
void checkOutputFolder(const std::string& path, const std::string& what) {
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    throwUsage(what + " " + path + ": the folder " + folder.string() + " does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throwUsage(what + " " + path + ": the folder " + folder.string() + " is not writable");
  }
}

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
    const auto& [option, path] = paths.outputs[i];
    if (path.empty()) continue;
    checkOutputFolder(path, option);
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
  }
}

}  // namespace plano::cli
