// Shared helpers of the fuzz targets: an invariant check that aborts (so that
// libFuzzer records the input as a crash) and a little-endian input reader.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

// Targets built on the C API (its header on their include path) also print the
// library's last message: a CI log then says why a call failed (which check
// refused a fitted model, say) without the input at hand. The format-only
// targets have no such message.
#if __has_include("sogmm/sogmm.h")
#include "sogmm/sogmm.h"
#define FUZZ_PRINT_LAST_ERROR() std::fprintf(stderr, "last sogmm error on this thread: %s\n", sogmm_last_error())
#else
#define FUZZ_PRINT_LAST_ERROR() ((void)0)
#endif

#define FUZZ_CHECK(cond)                                                                  \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      std::fprintf(stderr, "%s:%d: invariant violated: %s\n", __FILE__, __LINE__, #cond); \
      FUZZ_PRINT_LAST_ERROR();                                                            \
      std::abort();                                                                       \
    }                                                                                     \
  } while (0)

namespace sogmm_fuzz {

/// Consumes fixed-size values from the front of the input; past the end it
/// yields zeros.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : p_(data), n_(size) {}
  template <typename T>
  T take() {
    T v{};
    std::uint8_t buf[sizeof(T)] = {};
    const std::size_t k = n_ < sizeof(T) ? n_ : sizeof(T);
    if (k) std::memcpy(buf, p_, k);
    std::memcpy(&v, buf, sizeof(T));
    p_ += k;
    n_ -= k;
    return v;
  }
  const std::uint8_t* rest() const { return p_; }
  std::size_t remaining() const { return n_; }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
};

}  // namespace sogmm_fuzz
