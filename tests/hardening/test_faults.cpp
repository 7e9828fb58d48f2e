// Fault injection for saves and loads, beyond tests/format/test_save.cpp
// (which covers the injected open / half-write / fsync / rename failures and a
// missing directory): an unwritable directory, a real short write (file size
// limit, as on a full disk) through the format library and through the C API,
// every truncated prefix of a file through the C API, and loads racing with a
// writer that rewrites the file in place.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "sogmm/sogmm.h"
#include "scratch_dir_test.hpp"
#include "test_support.hpp"

namespace {

namespace fmt = sogmm::format;

class Faults : public sogmm::test::ScratchDirTest {
 protected:
  Faults() : ScratchDirTest("sogmm-hardening") {}
  static sogmm_model* capi_model(std::size_t m, std::uint32_t seed) {
    const sogmm::Model src = sogmm::test::synthetic_model(m, seed, false);
    sogmm_model* h = nullptr;
    EXPECT_EQ(sogmm_model_from_arrays_f32(&h, m, src.gmm.weights.data(), src.gmm.means.data(),
                                          src.gmm.covariances.data(), 100),
              SOGMM_OK)
        << sogmm_last_error();
    return h;
  }
};

TEST_F(Faults, SaveIntoAReadOnlyFileSystemFailsCleanly) {
  // /proc refuses new files even for root.
  const sogmm::Model m = sogmm::test::synthetic_model(3, 1);
  try {
    fmt::save("/proc/sogmm-hardening.sogmm", m);
    ADD_FAILURE() << "save into /proc succeeded";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Io) << e.what();
  }
  sogmm_model* h = capi_model(3, 1);
  EXPECT_EQ(sogmm_model_save(h, "/proc/sogmm-hardening.sogmm", nullptr), SOGMM_E_IO);
  EXPECT_NE(std::string(sogmm_last_error()).find("/proc"), std::string::npos) << sogmm_last_error();
  sogmm_model_free(h);
}

TEST_F(Faults, SaveIntoAnUnwritableDirectoryKeepsThePreviousFile) {
  const std::string path = dir_ + "/model.sogmm";
  fmt::save(path, sogmm::test::synthetic_model(3, 1));
  const std::vector<std::uint8_t> before = slurp(path);
  ASSERT_EQ(::chmod(dir_.c_str(), 0500), 0);
  if (::access(dir_.c_str(), W_OK) == 0) {
    ::chmod(dir_.c_str(), 0700);
    GTEST_SKIP() << "running with CAP_DAC_OVERRIDE (root): directory permissions are not enforced";
  }
  try {
    fmt::save(path, sogmm::test::synthetic_model(9, 2));
    ADD_FAILURE() << "save into a read-only directory succeeded";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Io) << e.what();
  }
  ::chmod(dir_.c_str(), 0700);
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(files(), std::vector<std::string>{"model.sogmm"});
}

// Runs `body` with the process's file size limit lowered to `limit` bytes and
// SIGXFSZ ignored: a write past the limit then fails with EFBIG, as a write
// to a full disk fails with ENOSPC, halfway through the file.
template <typename Body>
void with_file_size_limit(rlim_t limit, Body body) {
  struct rlimit old;
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  struct sigaction ignore {}, saved {};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGXFSZ, &ignore, &saved);
  struct rlimit lowered = old;
  lowered.rlim_cur = limit;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &lowered), 0);
  body();
  ::setrlimit(RLIMIT_FSIZE, &old);
  ::sigaction(SIGXFSZ, &saved, nullptr);
}

TEST_F(Faults, ShortWriteKeepsThePreviousFileAndLeavesNoTemporary) {
  const std::string path = dir_ + "/model.sogmm";
  const sogmm::Model old_model = sogmm::test::synthetic_model(2, 1);
  fmt::save(path, old_model);
  const std::vector<std::uint8_t> before = slurp(path);
  fmt::WriteOptions raw;
  raw.compress = false;
  const sogmm::Model big = sogmm::test::synthetic_model(2000, 3);  // ~ 120 KiB uncompressed
  ASSERT_GT(fmt::to_bytes(big, raw).size(), 64u << 10);
  with_file_size_limit(32 << 10, [&] {
    try {
      fmt::save(path, big, raw);
      ADD_FAILURE() << "save past the file size limit succeeded";
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), sogmm::ErrorCode::Io) << e.what();
    }
  });
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(files(), std::vector<std::string>{"model.sogmm"});
  EXPECT_TRUE(sogmm::test::bit_equal(fmt::load(path), old_model));
}

TEST_F(Faults, CapiShortWriteKeepsThePreviousFileAndLeavesNoTemporary) {
  const std::string path = dir_ + "/capi.sogmm";
  sogmm_model* old_model = capi_model(2, 1);
  ASSERT_EQ(sogmm_model_save(old_model, path.c_str(), nullptr), SOGMM_OK);
  const std::vector<std::uint8_t> before = slurp(path);
  sogmm_model* big = capi_model(2000, 4);
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_COMPRESS, 0), SOGMM_OK);
  with_file_size_limit(32 << 10, [&] {
    EXPECT_EQ(sogmm_model_save(big, path.c_str(), o), SOGMM_E_IO);
    EXPECT_NE(sogmm_last_error()[0], '\0');
  });
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(files(), std::vector<std::string>{"capi.sogmm"});
  // And the save works once the limit is gone.
  EXPECT_EQ(sogmm_model_save(big, path.c_str(), o), SOGMM_OK) << sogmm_last_error();
  sogmm_options_free(o);
  sogmm_model_free(big);
  sogmm_model_free(old_model);
}

TEST_F(Faults, InjectedFailureThenRetrySucceeds) {
  // A failed save (any stage) does not poison the next one to the same path.
  using fmt::detail::SaveStage;
  const std::string path = dir_ + "/retry.sogmm";
  const sogmm::Model m = sogmm::test::synthetic_model(5, 9);
  static std::atomic<int> calls{0};
  for (int fail_after = 0; fail_after < 4; ++fail_after) {
    calls = fail_after;
    fmt::detail::set_save_fault_hook([](SaveStage) { return calls.fetch_sub(1) == 0; });
    EXPECT_THROW(fmt::save(path, m), sogmm::Error);
    fmt::detail::set_save_fault_hook(nullptr);
    EXPECT_TRUE(files().empty()) << "after a failure at call " << fail_after;
    fmt::save(path, m);
    EXPECT_TRUE(sogmm::test::bit_equal(fmt::load(path), m));
    std::remove(path.c_str());
  }
}

TEST_F(Faults, CapiEveryTruncatedPrefixIsRejected) {
  sogmm_model* h = capi_model(6, 5);
  sogmm_buffer* buf = nullptr;
  ASSERT_EQ(sogmm_model_save_to_memory(&buf, h, nullptr), SOGMM_OK);
  const std::vector<std::uint8_t> full(sogmm_buffer_data(buf), sogmm_buffer_data(buf) + sogmm_buffer_size(buf));
  sogmm_buffer_free(buf);
  const std::string path = dir_ + "/prefix.sogmm";
  for (std::size_t n = 0; n < full.size(); ++n) {
    sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
    const std::uint8_t dummy = 0;
    EXPECT_EQ(sogmm_model_load_from_memory(&m, n ? full.data() : &dummy, n, nullptr), SOGMM_E_FORMAT) << n;
    EXPECT_EQ(m, nullptr);
    if (n % 7 == 0 || n + 1 == full.size()) {  // the file path too, on a sample of lengths
      std::ofstream(path, std::ios::binary | std::ios::trunc)
          .write(reinterpret_cast<const char*>(full.data()), static_cast<std::streamsize>(n));
      m = reinterpret_cast<sogmm_model*>(1);
      EXPECT_EQ(sogmm_model_load(&m, path.c_str(), nullptr), SOGMM_E_FORMAT) << n;
      EXPECT_EQ(m, nullptr);
    }
  }
  sogmm_model_free(h);
}

TEST_F(Faults, LoadRacingAnInPlaceRewriteNeverGivesAPartialModel) {
  // A writer rewrites the file in place (truncate, then write in chunks),
  // alternating two models; readers load concurrently. Every load is either a
  // complete, bit-exact copy of one of the two models or an error.
  const std::string path = dir_ + "/race.sogmm";
  const sogmm::Model a = sogmm::test::synthetic_model(50, 1, false);
  const sogmm::Model b = sogmm::test::synthetic_model(80, 2, false);
  const std::vector<std::uint8_t> bytes[2] = {fmt::to_bytes(a), fmt::to_bytes(b)};
  // What a complete read of each version gives (metadata included).
  const sogmm::Model ref[2] = {fmt::from_bytes(bytes[0].data(), bytes[0].size()),
                               fmt::from_bytes(bytes[1].data(), bytes[1].size())};
  fmt::save(path, a);
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (int round = 0; !stop; ++round) {
      const std::vector<std::uint8_t>& src = bytes[round % 2];
      std::FILE* f = std::fopen(path.c_str(), "wb");  // truncates
      if (!f) continue;
      for (std::size_t off = 0; off < src.size(); off += 97) {
        std::fwrite(src.data() + off, 1, std::min<std::size_t>(97, src.size() - off), f);
        std::fflush(f);
      }
      std::fclose(f);
    }
  });
  int loaded = 0, rejected = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
  while (std::chrono::steady_clock::now() < deadline) {
    try {
      const sogmm::Model m = fmt::load(path);
      ++loaded;
      EXPECT_TRUE(sogmm::test::bit_equal(m, ref[0]) || sogmm::test::bit_equal(m, ref[1]))
          << "a partial model was loaded";
    } catch (const sogmm::Error& e) {
      ++rejected;
      EXPECT_TRUE(e.code() == sogmm::ErrorCode::Format || e.code() == sogmm::ErrorCode::Io) << e.what();
    }
    sogmm_model* h = reinterpret_cast<sogmm_model*>(1);
    const sogmm_status s = sogmm_model_load(&h, path.c_str(), nullptr);
    if (s == SOGMM_OK) {
      std::size_t m = 0;
      EXPECT_EQ(sogmm_model_n_components(h, &m), SOGMM_OK);
      EXPECT_TRUE(m == 50 || m == 80) << m;
    } else {
      EXPECT_TRUE(s == SOGMM_E_FORMAT || s == SOGMM_E_IO) << s << ": " << sogmm_last_error();
      EXPECT_EQ(h, nullptr);
    }
    sogmm_model_free(h);
  }
  stop = true;
  writer.join();
  EXPECT_GT(loaded + rejected, 10);
  std::printf("racing loads: %d complete, %d rejected\n", loaded, rejected);
}

}  // namespace
