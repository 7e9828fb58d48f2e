// Shared helpers of the fuzz targets: an invariant check that aborts (so that
// libFuzzer records the input as a crash) and a little-endian input reader.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#define FUZZ_CHECK(cond)                                                          \
  do {                                                                            \
    if (!(cond)) {                                                                \
      std::fprintf(stderr, "%s:%d: invariant violated: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                               \
    }                                                                             \
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
