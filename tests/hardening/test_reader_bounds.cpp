// The .sogmm reader against hostile files (issue 13): a metadata length near
// 4 GiB, strings shared many times, decoding peaks, FIFOs and devices, float64
// values that float32 cannot hold, and metadata strings that are not UTF-8.
// Memory is measured with the hardening binary's heap accounting
// (heap_hook.hpp) against the bound of spec/format.md section 8.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <csignal>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "heap_hook.hpp"
#include "internal.hpp"
#include "schema.hpp"
#include "sogmm/format.hpp"
#include "sogmm/metadata_string.hpp"
#include "sogmm/sogmm.h"
#include "test_support.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define SOGMM_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SOGMM_TEST_ASAN 1
#endif
#endif

namespace {

namespace fmt = sogmm::format;
namespace det = sogmm::format::detail;
using sogmm::test::heap::live_bytes;
using sogmm::test::heap::peak_bytes;
using sogmm::test::heap::reset_peak;

constexpr long long kMiB = 1 << 20;

// The reference reader's peak heap for one file, spec/format.md section 8.1:
// 1 MiB + 2 L + 112 (E + 1) + 84 M + max_i k_i D_i (k_i = 2 for a float64 array).
double allowed_peak(const fmt::FileInfo& info, std::size_t entries) {
  double staging = 0;
  for (const fmt::ArrayInfo* a : {&info.weights, &info.means, &info.covariances}) {
    staging = std::max(staging, (a->dtype == "f64" ? 2.0 : 1.0) * static_cast<double>(a->decoded_length));
  }
  return static_cast<double>(kMiB) + 2.0 * static_cast<double>(info.metadata_length) +
         112.0 * static_cast<double>(entries + 1) + 84.0 * static_cast<double>(info.n_components) + staging;
}

// Peak heap growth while f runs.
template <typename F>
long long heap_peak_of(F&& f) {
  const long long base = live_bytes();
  reset_peak();
  f();
  return peak_bytes() - base;
}

// Runs fn in a forked child and returns its result (0..127), or 128 + the
// signal that ended it: a crash or a hang of the code under test fails the
// test instead of ending or blocking the whole binary. The child is killed
// after `seconds`. Without ASan (whose shadow memory needs a huge address
// space), the child's address space may grow by at most `extra_bytes`, so a
// reader that tries to swallow a huge file fails fast instead of using it.
int in_child(const std::function<int()>& fn, unsigned seconds, long long extra_bytes) {
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::alarm(seconds);
#ifndef SOGMM_TEST_ASAN
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (f != nullptr && std::fscanf(f, "%lu", &pages) == 1) {
      const rlim_t limit = static_cast<rlim_t>(pages) * static_cast<rlim_t>(::sysconf(_SC_PAGESIZE)) +
                           static_cast<rlim_t>(extra_bytes);
      const rlimit r{limit, limit};
      ::setrlimit(RLIMIT_AS, &r);
    }
    if (f != nullptr) std::fclose(f);
#else
    (void)extra_bytes;
#endif
    int code = 99;
    try {
      code = fn();
    } catch (...) {
      code = 98;
    }
    ::_exit(code);
  }
  int status = 0;
  if (pid < 0 || ::waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The reason of the FormatError that f throws, "accepted" or "other: ..." .
template <typename F>
std::string reason_of(F&& f) {
  try {
    f();
    return "accepted";
  } catch (const fmt::FormatError& e) {
    return e.reason();
  } catch (const std::exception& e) {
    return std::string("other: ") + e.what();
  }
}

class ReaderBounds : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = sogmm::test::make_scratch_dir("sogmm-reader-bounds"); }
  void TearDown() override { sogmm::test::remove_scratch_dir(dir_); }

  // A sparse file of `size` bytes with this header and the end marker.
  bool sparse_file(const std::string& path, std::uint64_t size, std::uint16_t major, std::uint32_t metadata_length) {
    std::uint8_t h[32] = {0x89, 'S', 'O', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
    det::store_le<std::uint16_t>(h + 8, major);
    det::store_le<std::uint64_t>(h + 16, size);
    det::store_le<std::uint32_t>(h + 24, metadata_length);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd < 0) return false;
    const bool ok = ::pwrite(fd, h, sizeof h, 0) == 32 && ::ftruncate(fd, static_cast<off_t>(size)) == 0 &&
                    ::pwrite(fd, "SGMM", 4, static_cast<off_t>(size - 4)) == 4;
    ::close(fd);
    return ok;
  }

  std::string write(const std::string& name, const std::vector<std::uint8_t>& bytes) {
    const std::string path = dir_ + "/" + name;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    EXPECT_NE(f, nullptr) << path;
    if (f != nullptr) {
      EXPECT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
      std::fclose(f);
    }
    return path;
  }

  std::string dir_;
};

// ---- finding 1 and 6: the header is checked before anything is read -------

TEST_F(ReaderBounds, HugeDeclaredMetadataIsRejectedFromTheHeaderAlone) {
  struct Case {
    const char* name;
    std::uint64_t size;
    std::uint16_t major;
    std::uint32_t metadata_length;
    const char* reason;
  };
  // 0xFFFFFFF9 + 7 wrapped a 32-bit sum (segfault after reading 4 GiB); a
  // block of 2^31 - 1 bytes is beyond what FlatBuffers can address; a 1 GiB
  // file of an unknown version needs only its header.
  const std::uint64_t wrap = 0xFFFFFFF9u;
  const Case cases[] = {
      {"wrap.sogmm", 32 + ((wrap + 7) & ~std::uint64_t{7}) + 4, 1, 0xFFFFFFF9u, "bad_header"},
      {"limit.sogmm", 32 + (std::uint64_t{1} << 31) + 4, 1, 0x7FFFFFFFu, "bad_header"},
      {"version.sogmm", std::uint64_t{1} << 30, 2, 1u << 29, "unsupported_version"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir_ + "/" + c.name;
    if (!sparse_file(path, c.size, c.major, c.metadata_length)) GTEST_SKIP() << "no sparse files in " << dir_;
    // In a child: the base reader crashed (or, under the address-space
    // limit, failed to allocate the whole file).
    const int rc = in_child(
        [&] {
          std::string got;
          const long long peak = heap_peak_of([&] { got = reason_of([&] { fmt::load(path); }); });
          if (got != c.reason) return 1;
          if (reason_of([&] { fmt::read_info_file(path); }) != c.reason) return 2;
          sogmm_model* m = nullptr;
          if (sogmm_model_load(&m, path.c_str(), nullptr) != SOGMM_E_FORMAT || m != nullptr) return 3;
          return peak <= 64 * 1024 ? 0 : 4;
        },
        60, 256 * kMiB);
    EXPECT_EQ(rc, 0) << "1 wrong reason from load, 2 from read_info_file, 3 C API status, 4 more than 64 KiB "
                        "allocated, >= 128 killed by a signal";
    ::unlink(path.c_str());
  }
}

// ---- finding 2: shared strings are counted once per use ----------------------

sogmm::Model with_shared_pairs(std::size_t pairs, std::size_t value_length) {
  sogmm::Model m = sogmm::test::synthetic_model(3, 1, false);
  m.producer_name = "p";
  m.producer_version = "1";
  m.key_values.assign(pairs, {"k", std::string(value_length, 'v')});
  return m;
}

std::vector<std::uint8_t> shared_file(const sogmm::Model& m) {
  det::Tweaks share;
  share.share_strings = true;
  return det::encode(m, {}, share);
}

TEST_F(ReaderBounds, StringsMayTotalAtMostTheMetadataLength) {
  // Two pairs sharing one key and one value: the block grows by the value's
  // length once, the decoded strings by twice that. Accepted exactly when
  // the strings (counted per use) total at most the block length L.
  int accepted = 0, rejected = 0;
  for (std::size_t v = 1; v < 1200; v += 7) {
    const sogmm::Model m = with_shared_pairs(2, v);
    const std::vector<std::uint8_t> file = shared_file(m);
    const std::uint64_t length = sogmm::test::le<std::uint32_t>(file, 24);
    const std::uint64_t total = 1 + 1 + 2 * (1 + v);  // producer name, version, two keys and values
    const std::string got = reason_of([&] { fmt::from_bytes(file.data(), file.size()); });
    if (total <= length) {
      EXPECT_EQ(got, "accepted") << "v = " << v << ": " << total << " string bytes, L = " << length;
      ++accepted;
    } else {
      EXPECT_EQ(got, "bad_metadata") << "v = " << v << ": " << total << " string bytes, L = " << length;
      EXPECT_EQ(reason_of([&] { fmt::read_info(file.data(), file.size()); }), "bad_metadata");
      ++rejected;
    }
  }
  EXPECT_GT(accepted, 10);
  EXPECT_GT(rejected, 10);
}

TEST_F(ReaderBounds, SharedStringsCannotAmplifyTheMetadata) {
  // 5000 pairs sharing a 4 KiB value: an 85 KB file whose strings would
  // decode to 20 MB. The check runs before any string is decoded.
  const std::vector<std::uint8_t> file = shared_file(with_shared_pairs(5000, 4 << 10));
  ASSERT_LT(file.size(), 100000u);
  const std::string path = write("amplified.sogmm", file);
  fmt::FileInfo header;  // what the bound is computed from
  header.metadata_length = sogmm::test::le<std::uint32_t>(file, 24);
  const double allowed = allowed_peak(header, 5000);
  std::string got;
  long long peak = heap_peak_of([&] { got = reason_of([&] { fmt::from_bytes(file.data(), file.size()); }); });
  EXPECT_EQ(got, "bad_metadata");
  EXPECT_LE(peak, allowed) << "from_bytes";
  peak = heap_peak_of([&] { got = reason_of([&] { fmt::load(path); }); });
  EXPECT_EQ(got, "bad_metadata");
  EXPECT_LE(peak, allowed) << "load";
  peak = heap_peak_of([&] { got = reason_of([&] { fmt::read_info_file(path); }); });
  EXPECT_EQ(got, "bad_metadata");  // sogmm-inspect --metadata
  EXPECT_LE(peak, allowed) << "read_info_file";
  sogmm_model* m = nullptr;
  EXPECT_EQ(sogmm_model_load(&m, path.c_str(), nullptr), SOGMM_E_FORMAT);
}

// ---- finding 6: decoding peaks near the size of the model --------------------

TEST_F(ReaderBounds, DecodingStaysWithinTheBoundOfTheSpec) {
  // Identical components compress to almost nothing (a zstd bomb within the
  // cap); the reader's peak must still be the model plus one frame of staging.
  const std::size_t m = std::size_t{1} << 16;
  sogmm::Model model = sogmm::test::synthetic_model(1, 3, false);
  model.gmm.weights[0] = 1.0f / static_cast<float>(m);
  const sogmm::Gmm one = model.gmm;
  model.gmm.resize(m);
  for (std::size_t k = 0; k < m; ++k) {
    model.gmm.weights[k] = one.weights[0];
    std::copy(one.means.begin(), one.means.end(), model.gmm.means.begin() + 4 * k);
    std::copy(one.covariances.begin(), one.covariances.end(), model.gmm.covariances.begin() + 16 * k);
  }
  model.key_values = {{"a", "b"}};
  model.producer_version = "1";  // as written (an empty one is replaced)
  for (bool f64 : {false, true}) {
    for (bool compress : {true, false}) {
      for (bool full : {false, true}) {
        SCOPED_TRACE(std::string(f64 ? "f64" : "f32") + (compress ? " zstd" : " raw") + (full ? " full" : " packed"));
        sogmm::Model variant = model;
        if (full) variant.gmm.covariances[1] = std::nextafter(variant.gmm.covariances[1], 1.0f);  // not bit-symmetric
        sogmm::Model returned = variant;  // a reader returns the symmetric part (spec/format.md 5.1)
        if (full) {
          returned.gmm.covariances[1] = returned.gmm.covariances[4] =
              sogmm::test::symmetric_tie(model.gmm.covariances[1], variant.gmm.covariances[1]);
        }
        const std::vector<std::uint8_t> file = fmt::to_bytes(variant, fmt::WriteOptions{1, f64, compress});
        const fmt::FileInfo info = fmt::read_info(file.data(), file.size());
        ASSERT_EQ(info.covariance_layout, full ? "full" : "upper_packed");
        const std::uint64_t decoded =
            info.weights.decoded_length + info.means.decoded_length + info.covariances.decoded_length;
        const double allowed = allowed_peak(info, 1);
        long long peak = heap_peak_of(
            [&] { EXPECT_TRUE(sogmm::test::bit_equal(fmt::from_bytes(file.data(), file.size()), returned)); });
        EXPECT_LE(peak, allowed) << "from_bytes: " << decoded << " decoded bytes from " << file.size();
        const std::string path = write("bomb.sogmm", file);
        peak = heap_peak_of([&] { EXPECT_TRUE(sogmm::test::bit_equal(fmt::load(path), returned)); });
        EXPECT_LE(peak, allowed) << "load (the file is never held whole)";
        std::printf("  %s %s %s: %zu-byte file, %llu decoded bytes, load peak %.2f x decoded (allowed %.2f)\n",
                    f64 ? "f64" : "f32", compress ? "zstd" : "raw ", full ? "full  " : "packed", file.size(),
                    static_cast<unsigned long long>(decoded), static_cast<double>(peak) / static_cast<double>(decoded),
                    allowed / static_cast<double>(decoded));
      }
    }
  }
}

TEST_F(ReaderBounds, ManyEntriesStayWithinTheBound) {
  // 99 990 distinct pairs (the FlatBuffers verifier allows 100 000 tables),
  // strings long enough to live on the heap.
  sogmm::Model m = sogmm::test::synthetic_model(1, 7, false);
  m.producer_version = "1";
  for (int i = 0; i < 99990; ++i) {
    char key[32], value[48];
    std::snprintf(key, sizeof key, "key-%020d", i);
    std::snprintf(value, sizeof value, "value-%030d", i);
    m.key_values.emplace_back(key, value);
  }
  const std::vector<std::uint8_t> file = fmt::to_bytes(m);
  const std::string path = write("entries.sogmm", file);
  const fmt::FileInfo info = fmt::read_info(file.data(), file.size());
  const long long peak = heap_peak_of([&] { EXPECT_EQ(fmt::load(path).key_values, m.key_values); });
  EXPECT_LE(peak, allowed_peak(info, m.key_values.size()));
}

TEST_F(ReaderBounds, AFrameThatPromisesMoreThanDeclaredIsRejectedBeforeDecoding) {
  // The weights' first frame replaced by the covariances' (whose content is
  // 10 times larger than all the weights): rejected from the frame header,
  // before any staging is allocated for it.
  const sogmm::Model model = sogmm::test::synthetic_model(4000, 4, false);
  std::vector<std::uint8_t> file = fmt::to_bytes(model, fmt::WriteOptions{1, false, true});
  const fmt::FileInfo info = fmt::read_info(file.data(), file.size());
  ASSERT_EQ(info.weights.codec, "zstd");
  ASSERT_EQ(info.covariances.codec, "zstd");
  ASSERT_GE(info.weights.stored_length, 32u);
  std::copy_n(file.begin() + static_cast<std::ptrdiff_t>(info.covariances.offset), 32,
              file.begin() + static_cast<std::ptrdiff_t>(info.weights.offset));
  fmt::ReadOptions unchecked;
  unchecked.verify_checksums = false;
  std::string got;
  const long long peak =
      heap_peak_of([&] { got = reason_of([&] { fmt::from_bytes(file.data(), file.size(), unchecked); }); });
  EXPECT_EQ(got, "decompression_failed");
  EXPECT_LE(peak, allowed_peak(info, 0) - static_cast<double>(info.covariances.decoded_length));
}

// ---- finding 5b: FIFOs, devices and directories ------------------------------

TEST_F(ReaderBounds, NonRegularFilesAreRefusedWithoutBlocking) {
  const std::string fifo = dir_ + "/pipe.sogmm";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  struct Case {
    std::string path, kind;
  };
  const Case cases[] = {{fifo, "FIFO"}, {"/dev/null", "device"}, {dir_, "directory"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.path);
    // Nobody writes the FIFO: a reader that opens it for reading blocks
    // forever (the child is killed after 20 s).
    const int rc = in_child(
        [&] {
          for (int entry = 0; entry < 2; ++entry) {
            try {
              if (entry == 0) fmt::load(c.path);
              if (entry == 1) fmt::read_info_file(c.path);
              return 1;
            } catch (const sogmm::Error& e) {
              if (e.code() != sogmm::ErrorCode::Io) return 2;
              if (std::string(e.what()).find(c.kind) == std::string::npos) return 3;
            }
          }
          sogmm_model* m = nullptr;
          if (sogmm_model_load(&m, c.path.c_str(), nullptr) != SOGMM_E_IO) return 4;
          return std::string(sogmm_last_error()).find(c.kind) == std::string::npos ? 5 : 0;
        },
        20, 256 * kMiB);
    EXPECT_EQ(rc, 0) << "1 accepted, 2 not Error(Io), 3 message does not say what the path is, 4 C API status, "
                        "5 C API message; 142 = SIGALRM: blocked";
  }
}

// ---- finding 10: float64 values are checked as the float32 model holds them ---

// A float64 file (raw, so values can be patched) of 2 components.
std::vector<std::uint8_t> f64_file() {
  sogmm::Model m = sogmm::test::synthetic_model(2, 5, false);
  return fmt::to_bytes(m, fmt::WriteOptions{1, true, false});
}

// The verdict of every entry point: format::from_bytes, format::load (what
// sogmm-inspect --verify runs), the C API from memory and from a file.
struct Verdicts {
  std::string from_bytes, load;
  sogmm_status capi_memory, capi_file;
};

sogmm_status status_for(const std::string& reason) {
  if (reason == "accepted") return SOGMM_OK;
  if (reason == "non_finite" || reason == "not_spd" || reason == "bad_weights" || reason == "not_symmetric") {
    return SOGMM_E_NUMERIC;
  }
  return SOGMM_E_FORMAT;
}

TEST_F(ReaderBounds, Float64ValuesGetOneVerdictFromEveryEntryPoint) {
  struct Case {
    const char* name;
    int array;
    std::vector<double> values;  // from element 0 of the array
    const char* expected;        // nullptr: whatever it is, the same everywhere
  };
  const double above_max = std::nextafter(static_cast<double>(FLT_MAX), 1e300);  // rounds to FLT_MAX
  const Case cases[] = {
      {"diagonal underflows to 0", det::kCovariances, {1e-50, 0, 0, 0, 1e-3, 0, 0, 1e-3, 0, 1e-3}, "not_spd"},
      {"diagonal becomes subnormal", det::kCovariances, {1e-40, 0, 0, 0, 1e-3, 0, 0, 1e-3, 0, 1e-3}, "accepted"},
      {"correlation rounds to 1", det::kCovariances, {1e-2, 1e-2 * (1 - 1e-12), 0, 0, 1e-2, 0, 0, 1e-3, 0, 1e-3},
       nullptr},
      {"mean overflows", det::kMeans, {1e39}, "non_finite"},
      {"mean rounds down to FLT_MAX", det::kMeans, {above_max}, "accepted"},
      {"weight underflows to 0", det::kWeights, {1e-50, 1.0}, "accepted"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::vector<std::uint8_t> file = f64_file();
    for (std::size_t i = 0; i < c.values.size(); ++i) det::patch_f64_value(file, c.array, i, c.values[i]);
    const std::string path = write("f64.sogmm", file);
    Verdicts v;
    v.from_bytes = reason_of([&] { fmt::from_bytes(file.data(), file.size()); });
    v.load = reason_of([&] { fmt::load(path); });
    sogmm_model* m = nullptr;
    v.capi_memory = sogmm_model_load_from_memory(&m, file.data(), file.size(), nullptr);
    sogmm_model_free(m);
    m = nullptr;
    v.capi_file = sogmm_model_load(&m, path.c_str(), nullptr);
    if (v.capi_file == SOGMM_OK && std::string(c.name) == "diagonal becomes subnormal") {
      float cov[32];
      ASSERT_EQ(sogmm_model_get_covariances_f32(m, cov, 32), SOGMM_OK);
      EXPECT_EQ(cov[0], static_cast<float>(1e-40));  // rounded to nearest, kept
    }
    sogmm_model_free(m);
    if (c.expected != nullptr) {
      EXPECT_EQ(v.from_bytes, c.expected);
    }
    EXPECT_EQ(v.load, v.from_bytes);
    EXPECT_EQ(v.capi_memory, status_for(v.from_bytes)) << sogmm_last_error();
    EXPECT_EQ(v.capi_file, status_for(v.from_bytes)) << sogmm_last_error();
  }
}

// ---- finding 9: one rule for metadata strings --------------------------------

// Independent truth for the UTF-8 rule: decode each sequence by the bit
// layout alone, and accept it when re-encoding its code point gives back as
// many bytes (no overlong form) and the code point is a non-NUL scalar value.
bool utf8_by_reencoding(const std::vector<unsigned char>& s) {
  for (std::size_t at = 0; at < s.size();) {
    const unsigned char b = s[at];
    const std::size_t len = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    if (len == 0 || at + len > s.size()) return false;
    std::uint32_t cp = len == 1 ? b : b & (0xFF >> (len + 1));
    for (std::size_t i = 1; i < len; ++i) {
      if ((s[at + i] >> 6) != 2) return false;
      cp = (cp << 6) | (s[at + i] & 0x3F);
    }
    if (cp == 0 || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    const std::size_t shortest = cp < 0x80 ? 1 : cp < 0x800 ? 2 : cp < 0x10000 ? 3 : 4;
    if (shortest != len) return false;
    at += len;
  }
  return true;
}

TEST(MetadataStrings, TheRuleIsExactlyUtf8WithoutNul) {
  // Every 1- and 2-byte sequence, every 3-byte one and the 4-byte ones around
  // each lead byte's limits.
  long long checked = 0;
  auto check = [&](std::vector<unsigned char> s) {
    const std::string text(s.begin(), s.end());
    const bool ours = sogmm::metadata_string_problem(text).empty();
    if (ours != utf8_by_reencoding(s)) {
      ADD_FAILURE() << "disagree on " << std::hex << int(s[0]) << " " << (s.size() > 1 ? int(s[1]) : -1);
    }
    // Repairing (file names stored by `sogmm fit`) keeps valid text and always follows the rule.
    const std::string repaired = sogmm::to_metadata_string(text);
    if (!sogmm::metadata_string_problem(repaired).empty() || (ours && repaired != text)) {
      ADD_FAILURE() << "to_metadata_string on " << std::hex << int(s[0]) << " " << (s.size() > 1 ? int(s[1]) : -1);
    }
    ++checked;
  };
  for (int a = 0; a < 256; ++a) {
    check({static_cast<unsigned char>(a)});
    for (int b = 0; b < 256; ++b) {
      check({static_cast<unsigned char>(a), static_cast<unsigned char>(b)});
      for (int c = 0; c < 256; ++c) {
        if (a >= 0xE0 && a <= 0xEF) {
          check({static_cast<unsigned char>(a), static_cast<unsigned char>(b), static_cast<unsigned char>(c)});
        }
      }
      if (a >= 0xF0) {
        for (unsigned char c : {0x7F, 0x80, 0xBF, 0xC0}) {
          check({static_cast<unsigned char>(a), static_cast<unsigned char>(b), c, 0x80});
        }
      }
    }
  }
  EXPECT_GT(checked, 1000000);
}

TEST_F(ReaderBounds, MetadataStringsFollowOneRuleEverywhere) {
  const std::vector<std::string> bad = {
      "caf\xe9",                   // Latin-1
      "\xc0\xaf",                  // overlong '/'
      "\xed\xa0\x80",              // surrogate U+D800
      "\xf4\x90\x80\x80",          // above U+10FFFF
      "ok\xe2\x82",                // truncated sequence
      std::string("a\0b", 3),      // NUL: C strings would cut it
  };
  det::Tweaks unchecked;
  unchecked.validate = false;
  for (const std::string& s : bad) {
    for (int field = 0; field < 4; ++field) {
      SCOPED_TRACE("field " + std::to_string(field) + ", bytes " + std::to_string(s.size()));
      sogmm::Model m = sogmm::test::synthetic_model(3, 6, false);
      m.key_values = {{"key", "value"}};
      if (field == 0) m.producer_name = s;
      if (field == 1) m.producer_version = s;
      if (field == 2) m.key_values[0].first = s;
      if (field == 3) m.key_values[0].second = s;
      // The writer refuses it...
      EXPECT_EQ(reason_of([&] { fmt::to_bytes(m); }), "bad_metadata");
      // ...the JSON dump refuses it (it used to replace bytes with U+FFFD)...
      EXPECT_EQ(reason_of([&] { fmt::to_canonical_json(m); }), "bad_metadata");
      // ...and every reader rejects a file that holds it.
      const std::vector<std::uint8_t> file = det::encode(m, {}, unchecked);
      EXPECT_EQ(reason_of([&] { fmt::from_bytes(file.data(), file.size()); }), "bad_metadata");
      EXPECT_EQ(reason_of([&] { fmt::read_info(file.data(), file.size()); }), "bad_metadata");
      sogmm_model* h = nullptr;
      EXPECT_EQ(sogmm_model_load_from_memory(&h, file.data(), file.size(), nullptr), SOGMM_E_FORMAT);
      EXPECT_EQ(h, nullptr);
    }
    // The C API's setter refuses what it can be given (no NUL in a C string).
    if (s.find('\0') == std::string::npos) {
      sogmm_model* h = nullptr;
      const std::vector<std::uint8_t> good = fmt::to_bytes(sogmm::test::synthetic_model(3, 6, false));
      ASSERT_EQ(sogmm_model_load_from_memory(&h, good.data(), good.size(), nullptr), SOGMM_OK);
      EXPECT_EQ(sogmm_model_set_value(h, s.c_str(), "v"), SOGMM_E_INVALID_ARG);
      EXPECT_EQ(sogmm_model_set_value(h, "k", s.c_str()), SOGMM_E_INVALID_ARG);
      sogmm_model_free(h);
    }
  }
  // Valid UTF-8 at the limits passes everywhere.
  sogmm::Model m = sogmm::test::synthetic_model(3, 6, false);
  m.producer_name = "\xf4\x8f\xbf\xbf";  // U+10FFFF
  m.key_values = {{"", "\xef\xbf\xbd"}, {"\x7f", "\xf0\x9f\x98\x80 \xe2\x80\xae"}};
  const std::vector<std::uint8_t> file = fmt::to_bytes(m);
  const sogmm::Model back = fmt::from_bytes(file.data(), file.size());
  EXPECT_EQ(back.producer_name, m.producer_name);
  EXPECT_EQ(back.key_values, m.key_values);
}

TEST(MetadataStrings, ARepeatedKeyGivesItsFirstPair) {
  // all_metadata (frozen, valid) repeats the key "note": every pair is kept
  // in order, and a lookup by key gives the first.
  const std::string path = std::string(SOGMM_CONFORMANCE_DIR) + "/valid/all_metadata.sogmm";
  sogmm_model* h = nullptr;
  ASSERT_EQ(sogmm_model_load(&h, path.c_str(), nullptr), SOGMM_OK) << sogmm_last_error();
  const char* value = nullptr;
  ASSERT_EQ(sogmm_model_get_value(h, "note", &value), SOGMM_OK);
  EXPECT_STREQ(value, "unicode \xce\xbb \xe2\x9c\x93");
  std::size_t n = 0;
  ASSERT_EQ(sogmm_model_value_count(h, &n), SOGMM_OK);
  EXPECT_EQ(n, 4u);
  sogmm_model_free(h);
}

}  // namespace
