#include "core/StagedFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>

#include "core/Error.h"

namespace plano {

StagedFile::StagedFile(std::filesystem::path target, std::string shown)
    : target_(std::move(target)), shown_(std::move(shown)) {
  std::random_device random;
  // Built by appending: GCC 12 warns falsely (-Wrestrict) on "." + string.
  std::string name = ".";
  name += target_.filename().string();
  name += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(random());
  const std::filesystem::path temporary = target_.parent_path() / name;
  fd_ = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0) throwBadInput(shown_ + ": cannot write (" + std::strerror(errno) + ")");
  temporary_ = temporary;
}

StagedFile::~StagedFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!temporary_.empty()) {
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
  }
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
}

}  // namespace plano
