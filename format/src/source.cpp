// Memory and file sources. POSIX only (as atomic_file.cpp).
#include "source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "sogmm/error.hpp"
#include "sogmm/input_file.hpp"

namespace sogmm::format::detail {
namespace {

[[noreturn]] void io_error(const std::string& what, const std::string& path, int err) {
  throw Error(ErrorCode::Io, what + " '" + path + "'" + (err != 0 ? std::string(": ") + std::strerror(err) : ""));
}

}  // namespace

void MemorySource::read(std::uint64_t offset, std::uint8_t* out, std::size_t n) const {
  if (data_ != nullptr && n != 0) std::memcpy(out, data_ + offset, n);  // from_bytes(nullptr, 0) reads nothing
}

const std::uint8_t* MemorySource::view(std::uint64_t offset, std::size_t) const { return data_ + offset; }

FileSource::FileSource(const std::string& path) : path_(path) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) io_error("cannot open", path, errno);
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    io_error("cannot determine the size of", path, err);
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw Error(ErrorCode::Io, "'" + path + "' is " + file_kind(st.st_mode) + ", not a regular .sogmm file");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

FileSource::~FileSource() { ::close(fd_); }

void FileSource::read(std::uint64_t offset, std::uint8_t* out, std::size_t n) const {
  while (n > 0) {
    const ssize_t got = ::pread(fd_, out, n, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) io_error("cannot read", path_, errno);
    if (got == 0) io_error("cannot read (the file became shorter while it was read)", path_, 0);
    out += got;
    offset += static_cast<std::uint64_t>(got);
    n -= static_cast<std::size_t>(got);
  }
}

}  // namespace sogmm::format::detail
