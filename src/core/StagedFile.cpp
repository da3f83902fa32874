#include "core/StagedFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>

#include "core/Error.h"

namespace plano {

namespace {

/// ".NAME.KINDPID-RANDOM" next to `target`.
std::filesystem::path sibling(const std::filesystem::path& target, const char* kind) {
  std::random_device random;
  // Built by appending: GCC 12 warns falsely (-Wrestrict) on "." + string.
  std::string name = ".";
  name += target.filename().string();
  name += kind + std::to_string(::getpid()) + "-" + std::to_string(random());
  return target.parent_path() / name;
}

}  // namespace

StagedFile::StagedFile(std::filesystem::path target, std::string shown)
    : target_(std::move(target)), shown_(std::move(shown)) {
  const std::filesystem::path temporary = sibling(target_, ".tmp");
  fd_ = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0) throwBadInput(shown_ + ": cannot write (" + std::strerror(errno) + ")");
  temporary_ = temporary;
}

StagedFile::~StagedFile() {
  if (fd_ >= 0) ::close(fd_);
  std::error_code ignored;
  if (!temporary_.empty()) std::filesystem::remove(temporary_, ignored);
  if (!previous_.empty()) std::filesystem::remove(previous_, ignored);
}

void StagedFile::write(const std::string& content, const std::function<void()>& between) {
  constexpr std::size_t kPiece = std::size_t{16} << 20;
  const auto failed = [&] { throwBadInput(shown_ + ": write failed (" + std::strerror(errno) + ")"); };
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    if (between) between();
    const ssize_t written = ::write(fd_, data, std::min(left, kPiece));
    if (written < 0) {
      if (errno == EINTR) continue;
      failed();
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  // On disk before the rename, so that a crash cannot leave an empty file in place of the old one.
  if (::fsync(fd_) != 0) failed();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) failed();
}

void StagedFile::commit() {
  std::error_code ec;
  std::filesystem::rename(temporary_, target_, ec);
  if (ec) throwBadInput(shown_ + ": cannot replace the file: " + ec.message());
  temporary_.clear();
  committed_ = true;
}

void StagedFile::keepPrevious() {
  struct stat info {};
  if (::lstat(target_.c_str(), &info) != 0) {
    kept_ = errno == ENOENT;  // nothing to keep: restoring removes the new file
    return;
  }
  const std::filesystem::path link = sibling(target_, ".old");
  if (::link(target_.c_str(), link.c_str()) != 0) return;
  previous_ = link;
  kept_ = true;
}

void StagedFile::restorePrevious() {
  if (!committed_ || !kept_) return;
  std::error_code ec;
  if (previous_.empty()) {
    std::filesystem::remove(target_, ec);
  } else {
    std::filesystem::rename(previous_, target_, ec);
    if (!ec) previous_.clear();  // a link that could not go back is removed with this object
  }
  committed_ = false;
}

}  // namespace plano
