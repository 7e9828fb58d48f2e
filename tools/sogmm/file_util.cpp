#include "file_util.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "sogmm/error.hpp"

namespace sogmm::tools {

void check_output_path(const std::string& path) {
  namespace fs = std::filesystem;
  require(!path.empty(), ErrorCode::InvalidArgument, "empty output path");
  const fs::path target(path);
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  require(fs::is_directory(parent, ec), ErrorCode::Io,
          path + ": cannot write (folder " + parent.string() + " does not exist)");
  require(!fs::is_directory(target, ec), ErrorCode::Io, path + ": cannot write (is a folder)");
}

void write_file_atomic(const std::string& path, const void* data, std::size_t size) {
  check_output_path(path);
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  require(fd >= 0, ErrorCode::Io, path + ": cannot write (" + std::strerror(errno) + ")");
  const auto* p = static_cast<const unsigned char*>(data);
  std::size_t left = size;
  int err = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      err = errno;
      break;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) {
    std::remove(tmp.c_str());
    throw Error(ErrorCode::Io, path + ": write failed (" + std::strerror(err) + ")");
  }
}

std::uint64_t file_size_or_zero(const std::string& path) {
  std::error_code ec;
  const auto n = std::filesystem::file_size(path, ec);
  return ec ? 0 : static_cast<std::uint64_t>(n);
}

}  // namespace sogmm::tools
