// Atomic file replacement: temporary file in the directory of the final
// target, write, fsync, rename over the target, fsync the directory. POSIX only.
//
// Symbolic links are written through, as editors and SQLite do: replacing the
// link itself would leave its target with the old model while the link's
// name showed the new one.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
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

// Length of the directory part of `path`, including its last '/' (0 for a bare name).
std::size_t directory_length(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? 0 : slash + 1;
}

std::string directory_of(const std::string& path) {
  const std::size_t n = directory_length(path);
  if (n == 0) return ".";
  if (n == 1) return "/";
  return path.substr(0, n - 1);
}

// As the kernel's limit on links followed in one path resolution (Linux's 40).
constexpr int kMaxLinkHops = 40;

std::string read_link(const std::string& path) {
  std::string target(256, '\0');
  for (;;) {
    const ssize_t n = ::readlink(path.c_str(), &target[0], target.size());
    if (n < 0) io_error("cannot read the symbolic link", path, errno);
    if (static_cast<std::size_t>(n) < target.size()) {
      target.resize(static_cast<std::size_t>(n));
      return target;
    }
    target.resize(2 * target.size());  // possibly truncated: read again with more room
  }
}

// The file a save to `path` replaces: `path`, or the end of its chain of
// symbolic links (which need not exist yet: a dangling link is written
// through and its target created). Links among the directories on the way
// are left to the kernel: rename() works through them.
std::string final_target(const std::string& path) {
  std::string p = path;
  for (int hops = 0;; ++hops) {
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    if (hops == kMaxLinkHops) io_error("cannot save to", path, ELOOP);
    const std::string target = read_link(p);
    p = !target.empty() && target[0] == '/' ? target : p.substr(0, directory_length(p)) + target;
  }
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

// Permission bits of the saved file: those of the file it replaces, without
// set-user-ID, set-group-ID and sticky bits (a model is not a program, and a
// copied set-ID bit on a file the caller now owns would be a privilege
// leak), or those of a new file.
mode_t mode_for(const std::string& target) {
  struct stat st;
  if (::stat(target.c_str(), &st) != 0) return new_file_mode();
  if (!S_ISREG(st.st_mode)) {
    throw Error(ErrorCode::Io, "cannot save to '" + target + "': it exists and is not a regular file");
  }
  return st.st_mode & 0777;
}

constexpr char kTempSuffix[] = ".tmp-XXXXXX";

// mkstemp() template next to `target`: its base name, cut so that the name
// with the suffix fits the directory's NAME_MAX (a valid 245-255 byte name
// would otherwise make every save fail). mkstemp() makes it unique.
std::string temp_template(const std::string& target) {
  const std::size_t dir_len = directory_length(target);
  const std::size_t suffix = sizeof kTempSuffix - 1;
  long name_max = ::pathconf(directory_of(target).c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = NAME_MAX;
  const std::size_t room = static_cast<std::size_t>(name_max) > suffix ? static_cast<std::size_t>(name_max) - suffix : 0;
  const std::size_t keep = std::min(target.size() - dir_len, room);
  return target.substr(0, dir_len + keep) + kTempSuffix;
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

void write_all(int fd, const std::uint8_t* p, std::size_t n, const std::string& path) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      io_error("cannot write", path, errno);
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
}

}  // namespace

void set_save_fault_hook(SaveFaultHook hook) { g_hook.store(hook); }

void atomic_write(const std::string& path, std::uint64_t size, const std::function<void(const ByteSink&)>& produce) {
  if (path.empty()) throw Error(ErrorCode::InvalidArgument, "save: empty path");
  const std::string target = final_target(path);
  const mode_t mode = mode_for(target);
  // The guard owns the name before mkstemp() creates the file: nothing that
  // can throw (allocation) stands between creating the file and guarding it.
  TempFile tmp;
  tmp.path = temp_template(target);
  tmp.fd = inject(SaveStage::Open) ? -1 : ::mkstemp(&tmp.path[0]);
  if (tmp.fd < 0) {
    tmp.keep = true;  // no file was created: nothing to remove
    io_error("cannot create a temporary file next to", target, errno);
  }
  ::fchmod(tmp.fd, mode);  // best effort: the file keeps mkstemp's 0600 otherwise

  // The fault hook's WriteHalf stage fires once the first half is written,
  // so that tests can make the write fail midway.
  const std::uint64_t half = size / 2;
  std::uint64_t written = 0;
  bool past_half = false;
  auto pass_half = [&] {
    past_half = true;
    if (inject(SaveStage::WriteHalf)) io_error("cannot write", tmp.path, errno);
  };
  produce([&](const std::uint8_t* p, std::size_t n) {
    while (n > 0) {
      if (!past_half && written >= half) pass_half();
      const std::size_t chunk = past_half ? n : static_cast<std::size_t>(std::min<std::uint64_t>(n, half - written));
      write_all(tmp.fd, p, chunk, tmp.path);
      p += chunk;
      n -= chunk;
      written += chunk;
    }
  });
  if (!past_half) pass_half();
  if (written != size) {
    throw std::logic_error("save: the encoder produced " + std::to_string(written) + " bytes, not the " +
                           std::to_string(size) + " it announced");
  }
  if (inject(SaveStage::Fsync) || ::fsync(tmp.fd) != 0) io_error("cannot flush", tmp.path, errno);
  const int close_result = ::close(tmp.fd);
  tmp.fd = -1;
  if (close_result != 0) io_error("cannot close", tmp.path, errno);
  if (inject(SaveStage::Rename) || ::rename(tmp.path.c_str(), target.c_str()) != 0) {
    io_error("cannot rename the temporary file onto", target, errno);
  }
  tmp.keep = true;
  // Make the rename durable; failure here does not undo the (complete) save.
  const int dir = ::open(directory_of(target).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace sogmm::format::detail
