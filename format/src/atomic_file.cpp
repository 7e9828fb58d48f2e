// Atomic file replacement: temporary file in the same directory, write,
// fsync, rename, fsync the directory. POSIX only.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "internal.hpp"

namespace sogmm::format::detail {
namespace {

std::atomic<SaveFaultHook> g_hook{nullptr};

bool inject(SaveStage stage) {
  const SaveFaultHook hook = g_hook.load();
  if (hook != nullptr && hook(stage)) {
    errno = EIO;
    return true;
  }
  return false;
}

[[noreturn]] void io_error(const std::string& what, const std::string& path, int err) {
  throw Error(ErrorCode::Io, what + " '" + path + "': " + std::strerror(err));
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// Permission bits for a new file: 0666 minus the process umask, read from
// /proc (changing the umask to read it would not be thread-safe).
mode_t new_file_mode() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(0666 & ~std::strtoul(line.c_str() + 6, nullptr, 8));
  }
  return 0644;
}

// Removes the temporary file unless released.
struct TempFile {
  std::string path;
  int fd = -1;
  bool keep = false;
  ~TempFile() {
    if (fd >= 0) ::close(fd);
    if (!keep) ::unlink(path.c_str());
  }
};

}  // namespace

void set_save_fault_hook(SaveFaultHook hook) { g_hook.store(hook); }

void atomic_write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  if (path.empty()) throw Error(ErrorCode::InvalidArgument, "save: empty path");
  std::string name = path + ".tmp-XXXXXX";
  std::vector<char> templ(name.begin(), name.end());
  templ.push_back('\0');
  const int fd = inject(SaveStage::Open) ? -1 : ::mkstemp(templ.data());
  if (fd < 0) io_error("cannot create a temporary file next to", path, errno);
  TempFile tmp;
  tmp.path = templ.data();
  tmp.fd = fd;

  struct stat st;
  const mode_t mode = ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 07777) : new_file_mode();
  ::fchmod(fd, mode);

  // Written in two halves so that tests can make the write fail midway.
  auto write_all = [&](const std::uint8_t* p, std::size_t n) {
    while (n > 0) {
      const ssize_t w = ::write(fd, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        io_error("cannot write", tmp.path, errno);
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
  };
  const std::size_t half = bytes.size() / 2;
  write_all(bytes.data(), half);
  if (inject(SaveStage::WriteHalf)) io_error("cannot write", tmp.path, errno);
  write_all(bytes.data() + half, bytes.size() - half);
  if (inject(SaveStage::Fsync) || ::fsync(fd) != 0) io_error("cannot flush", tmp.path, errno);
  const int close_result = ::close(tmp.fd);
  tmp.fd = -1;
  if (close_result != 0) io_error("cannot close", tmp.path, errno);
  if (inject(SaveStage::Rename) || ::rename(tmp.path.c_str(), path.c_str()) != 0) {
    io_error("cannot rename the temporary file onto", path, errno);
  }
  tmp.keep = true;
  // Make the rename durable; failure here does not undo the (complete) save.
  const int dir = ::open(directory_of(path).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace sogmm::format::detail
