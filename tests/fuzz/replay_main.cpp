// Replays inputs through a fuzz target without libFuzzer: every file given
// on the command line, and every regular file of every directory given, is
// passed once to LLVMFuzzerTestOneInput. A crash (or sanitizer report) fails
// the test; otherwise prints how many inputs ran.
#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

int run_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "cannot read %s\n", path.c_str());
    return 0;
  }
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A copy of exactly `size` bytes, so that ASan sees any over-read.
  std::vector<std::uint8_t> exact(bytes.begin(), bytes.end());
  LLVMFuzzerTestOneInput(exact.empty() ? nullptr : exact.data(), exact.size());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  int count = 0;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    struct stat st;
    if (::stat(arg.c_str(), &st) != 0) continue;  // optional folders may be absent
    if (S_ISDIR(st.st_mode)) {
      std::vector<std::string> names;
      if (DIR* d = ::opendir(arg.c_str())) {
        while (dirent* e = ::readdir(d)) {
          const std::string n = e->d_name;
          if (n != "." && n != ".." && n != "README.md") names.push_back(arg + "/" + n);
        }
        ::closedir(d);
      }
      std::sort(names.begin(), names.end());
      for (const std::string& n : names) {
        struct stat fs;
        if (::stat(n.c_str(), &fs) == 0 && S_ISREG(fs.st_mode)) count += run_file(n);
      }
    } else {
      count += run_file(arg);
    }
  }
  std::printf("replayed %d inputs\n", count);
  return 0;
}
