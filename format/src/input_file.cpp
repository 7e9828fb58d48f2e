// Small input files (images, trajectories) read whole, by one rule for all:
// a regular file only, opened without blocking, of bounded size.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "sogmm/error.hpp"
#include "sogmm/input_file.hpp"

namespace sogmm::format {

const char* file_kind(unsigned mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return "not a regular file";
}

namespace {
// Closes the descriptor on every way out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};
}  // namespace

std::string read_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  require(f.fd >= 0, ErrorCode::Io, path + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  struct stat st {};
  const bool stat_ok = ::fstat(f.fd, &st) == 0;
  if (!stat_ok || !S_ISREG(st.st_mode))
    throw Error(ErrorCode::Io, path + ": cannot read " + what + " (" +
                                   (stat_ok ? std::string("it is ") + file_kind(st.st_mode) + ", not a regular file"
                                            : std::string("cannot stat it")) +
                                   ")");
  require(static_cast<std::uint64_t>(st.st_size) <= max_bytes, ErrorCode::Limit,
          path + ": " + what + " of " + std::to_string(st.st_size) + " bytes exceeds the limit of " +
              std::to_string(max_bytes) + " bytes");
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    require(n >= 0, ErrorCode::Io, path + ": cannot read " + what + " (" + std::strerror(errno) + ")");
    if (n == 0) break;
    // A file that grows while it is read stays under the limit too.
    require(text.size() + static_cast<std::size_t>(n) <= max_bytes, ErrorCode::Limit,
            path + ": " + what + " exceeds the limit of " + std::to_string(max_bytes) + " bytes");
    text.append(buf, static_cast<std::size_t>(n));
  }
  return text;
}

}  // namespace sogmm::format
