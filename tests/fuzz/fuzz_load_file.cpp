// Fuzz target: format::load and format::read_info_file on a file holding the
// input (a per-process temporary file, rewritten for every input). A file
// that loads must also pass read_info_file with the same M; every failure is a
// sogmm::Error (never another exception, never a crash).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz_util.hpp"
#include "sogmm/format.hpp"

namespace {

// Per process, and of a fixed length (the pid zero-padded), so that the
// length of the path in error messages is the same in every run: a seeded
// run must execute the same code whatever the pid.
std::string temp_path() {
  const char* dir = std::getenv("TMPDIR");
  char pid[24];
  std::snprintf(pid, sizeof pid, "%010ld", static_cast<long>(::getpid()));
  return std::string(dir && *dir ? dir : "/tmp") + "/sogmm-fuzz-load-file-" + pid + ".sogmm";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = temp_path();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    FUZZ_CHECK(f != nullptr);
    if (size) FUZZ_CHECK(std::fwrite(data, 1, size, f) == size);
    std::fclose(f);
  }
  sogmm::format::ReadOptions options;
  options.max_decoded_bytes = 4 << 20;
  bool loaded = false;
  std::uint64_t m = 0;
  try {
    const sogmm::Model model = sogmm::format::load(path, options);
    loaded = true;
    m = model.gmm.size();
    FUZZ_CHECK(m >= 1 && model.gmm.means.size() == 4 * m && model.gmm.covariances.size() == 16 * m);
  } catch (const sogmm::Error& e) {
    FUZZ_CHECK(e.code() != sogmm::ErrorCode::Io);  // the file exists and is readable
  }
  try {
    const sogmm::format::FileInfo info = sogmm::format::read_info_file(path, options);
    FUZZ_CHECK(info.file_length == size);
    if (loaded) FUZZ_CHECK(info.n_components == m);
  } catch (const sogmm::Error& e) {
    FUZZ_CHECK(!loaded);  // what loads fully has a valid header and metadata
    FUZZ_CHECK(e.code() != sogmm::ErrorCode::Io);
  }
  std::remove(path.c_str());
  return 0;
}
