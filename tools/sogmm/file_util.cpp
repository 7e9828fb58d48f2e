#include "file_util.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "sogmm/error.hpp"
#include "sogmm/format.hpp"
#include "sogmm/input_file.hpp"

namespace sogmm::tools {

namespace fs = std::filesystem;

namespace {
// The same file as far as can be told before it exists: equal when both
// exist and are one inode (hard links, symbolic links), else when their
// paths resolve to the same name.
bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  const fs::path ca = fs::weakly_canonical(a, ec);
  if (ec) return a == b;
  const fs::path cb = fs::weakly_canonical(b, ec);
  return ec ? a == b : ca == cb;
}
}  // namespace

void write_file_atomic(const std::string& path, const void* data, std::size_t size) {
  try {
    format::write_file(path, data, size);
  } catch (const Error& e) {
    const std::string what = e.what();
    throw Error(e.code(), what.find(path) != std::string::npos ? what : path + ": " + what);
  }
}

void check_output_path(const std::string& path) {
  require(!path.empty(), ErrorCode::InvalidArgument, "empty output path");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {  // through symbolic links: the file a write replaces
    require(S_ISREG(st.st_mode), ErrorCode::Io,
            path + ": cannot write (it is " + format::file_kind(st.st_mode) + ", not a regular file)");
  }
  // The folder of the final target: a temporary file is created there.
  std::error_code ec;
  fs::path target(path);
  for (int hops = 0; hops < 40 && fs::is_symlink(target, ec); ++hops) {
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) break;
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  const fs::path parent = target.has_parent_path() ? target.parent_path() : fs::path(".");
  require(fs::is_directory(parent, ec), ErrorCode::Io,
          path + ": cannot write (folder " + parent.string() + " does not exist)");
  // Creating a file is the one test that holds for every reason it can fail
  // (permissions, ACLs, a read-only file system, root's exemptions).
  std::string probe = (parent / ".sogmm-probe-XXXXXX").string();
  const int fd = ::mkstemp(&probe[0]);
  require(fd >= 0, ErrorCode::Io,
          path + ": cannot write in folder " + parent.string() + " (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

void check_outputs(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedFile& out = outputs[i];
    if (out.path.empty()) continue;
    check_output_path(out.path);
    for (const NamedFile& in : inputs)
      require(in.path.empty() || !same_file(out.path, in.path), ErrorCode::InvalidArgument,
              out.flag + " " + out.path + " is also the input " + in.flag + " " + in.path +
                  ": writing it would destroy the input");
    for (std::size_t j = 0; j < i; ++j)
      require(outputs[j].path.empty() || !same_file(out.path, outputs[j].path), ErrorCode::InvalidArgument,
              out.flag + " " + out.path + " is the same file as " + outputs[j].flag + " " + outputs[j].path +
                  ": give each output its own file");
  }
}

std::string read_input_file(const std::string& path, const std::string& what) {
  return format::read_input_file(path, what, kMaxInputFileBytes);
}

std::uint64_t file_size_or_zero(const std::string& path) {
  std::error_code ec;
  const auto n = fs::file_size(path, ec);
  return ec ? 0 : static_cast<std::uint64_t>(n);
}

}  // namespace sogmm::tools
