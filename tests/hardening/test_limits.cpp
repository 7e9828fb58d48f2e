// Resource limits: fits refuse sizes beyond sogmm::kMaxPoints /
// kMaxComponents with ErrorCode::Limit (SOGMM_E_LIMIT) before reading or
// allocating, and the reader's heap use is bounded by a small multiple of
// ReadOptions::max_decoded_bytes (plus the file itself) whatever the file says.
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <dirent.h>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "heap_hook.hpp"
#include "internal.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/format.hpp"
#include "sogmm/mean_shift.hpp"
#include "capi_calls.hpp"
#include "sogmm/sogmm.h"
#include "test_support.hpp"

// Heap accounting: heap_hook.cpp replaces operator new for this executable.
namespace heap = sogmm::test::heap;

namespace {

namespace fmt = sogmm::format;

// ---- fit limits -------------------------------------------------------------

TEST(CoreLimits, TooManyPointsIsRefusedBeforeReadingThem) {
  // A view declaring kMaxPoints + 1 points over a 4-point buffer: the limit is
  // checked first, so the buffer is never read past its end.
  const std::vector<float> four(16, 0.5f);
  for (std::size_t k : {std::size_t{0}, std::size_t{3}}) {
    sogmm::FitOptions o;
    o.n_components = k;
    try {
      sogmm::fit(sogmm::PointsView{four.data(), sogmm::kMaxPoints + 1}, o);
      ADD_FAILURE() << "fit accepted N = kMaxPoints + 1";
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
      EXPECT_NE(std::string(e.what()).find("limit"), std::string::npos) << e.what();
    }
  }
}

std::vector<float> spread_points(std::size_t n) {
  // Distinct ranges 5 cm apart along z: with bandwidth 0.02 every point is its own mode.
  std::vector<float> p(4 * n);
  for (std::size_t i = 0; i < n; ++i) {
    p[4 * i + 0] = 0.0f;
    p[4 * i + 1] = 0.0f;
    p[4 * i + 2] = 0.5f + 0.05f * static_cast<float>(i);
    p[4 * i + 3] = 0.5f;
  }
  return p;
}

TEST(CoreLimits, TooManyComponentsIsRefused) {
  const std::size_t n = sogmm::kMaxComponents + 1;
  const std::vector<float> pts = spread_points(n);
  sogmm::FitOptions o;
  o.n_components = n;  // K <= N, but over the limit
  try {
    sogmm::fit(sogmm::PointsView{pts.data(), n}, o);
    ADD_FAILURE() << "fit accepted K = kMaxComponents + 1";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
  }
  // K > N stays an invalid argument, whatever its size.
  o.n_components = n + 1;
  try {
    sogmm::fit(sogmm::PointsView{pts.data(), n}, o);
    ADD_FAILURE();
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument) << e.what();
  }
}

TEST(CoreLimits, ModeCountOverTheComponentLimitIsRefused) {
  const std::size_t n = sogmm::kMaxComponents + 100;
  const std::vector<float> pts = spread_points(n);
  sogmm::FitOptions o;  // self-organizing, bandwidth 0.02: n modes
  o.em.threads = 1;
  try {
    sogmm::fit(sogmm::PointsView{pts.data(), n}, o);
    ADD_FAILURE() << "self-organizing fit ran with more than kMaxComponents modes";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
    EXPECT_NE(std::string(e.what()).find("bandwidth"), std::string::npos) << e.what();
  }
}

TEST(CapiLimits, ComponentLimitMapsToSogmmELimit) {
  const std::size_t n = sogmm::kMaxComponents + 1;
  const std::vector<float> pts = spread_points(n);
  sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
  EXPECT_EQ(sogmm_test::fit_fixed_k(&m, pts.data(), n, n, nullptr), SOGMM_E_LIMIT) << sogmm_last_error();
  EXPECT_EQ(m, nullptr);
  EXPECT_NE(std::string(sogmm_last_error()).find("limit"), std::string::npos) << sogmm_last_error();
}

TEST(CapiLimits, PointLimitMapsToSogmmELimit) {
  // kMaxPoints + 1 real points (1 GiB of zero pages, reserved lazily: reading
  // them maps the shared zero page, so this costs no real memory).
  const std::size_t n = sogmm::kMaxPoints + 1;
  const std::size_t bytes = n * 4 * sizeof(float);
  void* region = ::mmap(nullptr, bytes, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (region == MAP_FAILED) GTEST_SKIP() << "cannot reserve 1 GiB of address space";
  sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
  EXPECT_EQ(sogmm_test::fit_fixed_k(&m, static_cast<const float*>(region), n, 2, nullptr), SOGMM_E_LIMIT)
      << sogmm_last_error();
  EXPECT_EQ(m, nullptr);
  ::munmap(region, bytes);
}

// Mode counting on a few points spread over a huge range: the neighbour grid
// used to have one cell per bandwidth (here 7.5e7 cells, 600 MB for 64
// points; found by fuzz_fit). Its size is now bounded by the number of points.
TEST(CoreLimits, ModeCountMemoryDoesNotGrowWithTheExtent) {
  std::vector<float> pts;
  for (int i = 0; i < 64; ++i) {
    const float z = 1.0f + 1.5e6f * static_cast<float>(i) / 63.0f;
    pts.insert(pts.end(), {0.0f, 0.0f, z, 0.5f});
  }
  const sogmm::PointsView view{pts.data(), 64};
  for (auto counter : {sogmm::ModeCounter::FlatBinned, sogmm::ModeCounter::GaussianBlurring}) {
    sogmm::FitOptions o;
    o.mode_counter = counter;
    o.em.threads = 1;
    const long long base = heap::live_bytes();
    heap::reset_peak();
    const sogmm::FitResult r = sogmm::fit(view, o);
    EXPECT_EQ(r.gmm.size(), 64u);  // every point is its own mode
    EXPECT_LT(heap::peak_bytes() - base, 64 << 20) << "the mode count allocated " << (heap::peak_bytes() - base) << " bytes";
  }
}

// Coordinates whose ratio to the bandwidth does not fit the 64-bit grid and
// bin indices are refused with a clear error (was undefined behaviour, a
// float-to-integer overflow; regressions/fit/grid_index_overflow).
TEST(CoreLimits, CoordinatesTooLargeForTheBandwidthAreRefused) {
  const std::vector<float> far = {1e30f, 0, 0, 0.5f, -1e30f, 0, 0, 0.5f, 0, 1e30f, 2e30f, 0.1f};
  const std::vector<float> near_far = {3e20f, 0, 0, 0.5f, 3e20f, 0, 0, 0.5f};  // extent 0, huge values
  for (const auto* cloud : {&far, &near_far}) {
    for (auto counter : {sogmm::ModeCounter::FlatBinned, sogmm::ModeCounter::GaussianBlurring}) {
      for (auto anchor : {sogmm::BinAnchor::Zero, sogmm::BinAnchor::DataMin}) {
        sogmm::FitOptions o;
        o.mode_counter = counter;
        o.mean_shift.anchor = anchor;
        try {
          sogmm::fit(sogmm::PointsView{cloud->data(), cloud->size() / 4}, o);
          ADD_FAILURE() << "fit accepted coordinates of 1e30 with bandwidth 0.02";
        } catch (const sogmm::Error& e) {
          EXPECT_EQ(e.code(), sogmm::ErrorCode::Limit) << e.what();
          EXPECT_NE(std::string(e.what()).find("larger bandwidth"), std::string::npos) << e.what();
        }
      }
    }
  }
  // With a bandwidth to match, the same far-away cloud fits.
  sogmm::FitOptions o;
  o.bandwidth = 1e20;
  EXPECT_NO_THROW(sogmm::fit(sogmm::PointsView{near_far.data(), 2}, o));
}

// A bandwidth whose square or inverse square is not a finite non-zero double
// is refused up front with its exact value in the message (4e-314 made the
// blurring kernel 0 * inf = NaN and the grid cast NaN to an integer:
// regressions/fit/blurring_bandwidth_denormal). The boundary is where
// 1 / (2 bw^2) overflows: about 5.3e-155.
TEST(CoreLimits, BandwidthWhoseInverseSquareOverflowsIsRefused) {
  const std::vector<float> cloud = {0, 0, 1, 0.5f, 0, 0, 1, 0.5f, 0.01f, 0, 1, 0.5f};
  for (double bw : {4e-314, 1e-160, 5e-155, 5e153, 1e155, 1e300}) {
    EXPECT_FALSE(sogmm::bandwidth_is_usable(bw)) << bw;
    for (auto counter : {sogmm::ModeCounter::FlatBinned, sogmm::ModeCounter::GaussianBlurring}) {
      sogmm::FitOptions o;
      o.mode_counter = counter;
      o.bandwidth = bw;
      try {
        sogmm::fit(sogmm::PointsView{cloud.data(), cloud.size() / 4}, o);
        ADD_FAILURE() << "fit accepted bandwidth " << bw;
      } catch (const sogmm::Error& e) {
        EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument) << e.what();
        EXPECT_NE(std::string(e.what()).find(sogmm::checked::exact(bw)), std::string::npos) << e.what();
      }
    }
  }
  for (double bw : {6e-155, 1e-100, 0.02, 1e100, 4e153}) EXPECT_TRUE(sogmm::bandwidth_is_usable(bw)) << bw;
  // Both mean shifts refuse it directly too.
  const std::vector<double> xy = {1.0, 0.5, 1.0, 0.5};
  EXPECT_THROW(sogmm::mean_shift_gaussian_blurring(xy, 4e-314), sogmm::Error);
  EXPECT_THROW(sogmm::mean_shift_flat(xy, 4e-314), sogmm::Error);
}

// ---- reader memory bound ----------------------------------------------------

// Peak heap growth (bytes) while reading `file` with the given cap; the
// reader's verdict goes to *ok.
long long peak_during_read(const std::vector<std::uint8_t>& file, std::uint64_t cap, bool* ok) {
  fmt::ReadOptions r;
  r.max_decoded_bytes = cap;
  const long long base = heap::live_bytes();
  heap::reset_peak();
  try {
    const sogmm::Model m = fmt::from_bytes(file.data(), file.size(), r);
    *ok = true;
  } catch (const sogmm::Error&) {
    *ok = false;
  }
  return heap::peak_bytes() - base;
}

// The bound that the reader keeps (spec/format.md section 8's cap on decoded
// bytes D): peak heap <= file size + kReadFactor * min(D, cap) + kSlack.
// Decoding keeps the float32 model and one array's staging at a time: at most
// 2.45 x D for any mix of dtypes (section 8.1).
constexpr double kReadFactor = 2.45;
constexpr long long kSlack = 256 << 10;

TEST(ReaderCap, PeakHeapIsBoundedByTheDecodedCap) {
  const std::uint64_t cap = 8u << 20;
  int checked = 0;
  double worst = 0;  // largest (peak - file size) / decoded bytes seen
  for (bool f64 : {false, true}) {
    for (bool compress : {false, true}) {
      for (std::size_t m : {std::size_t{1}, std::size_t{1000}, std::size_t{20000}}) {
        const sogmm::Model model = sogmm::test::synthetic_model(m, 5, false);
        fmt::WriteOptions w;
        w.float64 = f64;
        w.compress = compress;
        w.zstd_level = 1;
        const std::vector<std::uint8_t> file = fmt::to_bytes(model, w);
        const fmt::FileInfo info = fmt::read_info(file.data(), file.size());
        const std::uint64_t decoded =
            info.weights.decoded_length + info.means.decoded_length + info.covariances.decoded_length;
        bool ok = false;
        const long long peak = peak_during_read(file, cap, &ok);
        EXPECT_EQ(ok, decoded <= cap) << m << " components, " << decoded << " decoded bytes";
        const double bound = static_cast<double>(file.size()) +
                             kReadFactor * static_cast<double>(std::min<std::uint64_t>(decoded, cap)) + kSlack;
        EXPECT_LE(static_cast<double>(peak), bound)
            << m << " components (f64 " << f64 << ", zstd " << compress << "): peak " << peak << " for "
            << decoded << " decoded bytes in a file of " << file.size();
        if (decoded > 100000)
          worst = std::max(worst, (static_cast<double>(peak) - static_cast<double>(file.size())) / decoded);
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 12);
  std::printf("reader peak heap: at most %.2f x the decoded bytes beyond the file size\n", worst);
}

TEST(ReaderCap, TinyHostileFilesCannotAllocateBeyondTheCap) {
  // Files that declare a huge M (lengths following it) over tiny arrays: the
  // declared size is over the cap (refused before allocating) or under it
  // (allocation bounded by the cap, then the short data is rejected).
  const sogmm::Model small = sogmm::test::synthetic_model(4, 3, false);
  for (std::uint64_t declared : {std::uint64_t{1} << 14, std::uint64_t{1} << 20, std::uint64_t{1} << 40}) {
    for (bool compress : {false, true}) {
      fmt::detail::Tweaks t;
      t.n_components = declared;
      t.lengths_follow_declared_m = true;
      fmt::WriteOptions w;
      w.compress = compress;
      const std::vector<std::uint8_t> file = fmt::detail::encode(small, w, t);
      for (std::uint64_t cap : {std::uint64_t{1} << 20, fmt::kDefaultMaxDecodedBytes}) {
        bool ok = true;
        const long long peak = peak_during_read(file, cap, &ok);
        EXPECT_FALSE(ok);
        const double bound = static_cast<double>(file.size()) + kReadFactor * static_cast<double>(cap) + kSlack;
        EXPECT_LE(static_cast<double>(peak), bound) << "declared M " << declared << ", cap " << cap;
        EXPECT_LE(peak, 64 << 20) << "declared M " << declared << ", cap " << cap
                                  << ": a small file made the reader allocate " << peak << " bytes";
      }
    }
  }
}

TEST(ReaderCap, InvalidConformanceVectorsStayUnderTheBound) {
  const std::string dir = std::string(SOGMM_CONFORMANCE_DIR) + "/invalid";
  DIR* d = ::opendir(dir.c_str());
  ASSERT_NE(d, nullptr) << dir;
  int n = 0;
  while (dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() < 6 || name.substr(name.size() - 6) != ".sogmm") continue;
    std::ifstream in(dir + "/" + name, std::ios::binary);
    const std::vector<std::uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bool ok = true;
    const std::uint64_t cap = 1u << 20;
    const long long peak = peak_during_read(file, cap, &ok);
    EXPECT_FALSE(ok) << name;
    EXPECT_LE(static_cast<double>(peak), file.size() + kReadFactor * cap + kSlack) << name;
    ++n;
  }
  ::closedir(d);
  EXPECT_GT(n, 20);
}

}  // namespace
