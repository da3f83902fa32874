#include "plano/OutputGuard.h"

#include <sys/stat.h>

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

}  // namespace

void checkOutputPath(const std::string& input, const std::string& output, bool inPlace) {
  if (inPlace || input.empty() || output.empty()) return;
  if (canonicalForm(input) == canonicalForm(output) || sameInode(input, output)) {
    throwUsage("output " + output + " is the input file " + input +
               ": refusing to overwrite it (write elsewhere, or pass --in-place)");
  }
}

}  // namespace plano::cli
