// Fuzz target: the verification entry points of the format library on bytes
// in memory: read_info (header + metadata only), from_bytes with and without
// checksum verification, and the canonical JSON dump of what was read.
// Invariants: a full read implies a successful read_info with the same M; a
// read with checksums implies a read without; an accepted model re-encodes
// and reads back bit-exactly.
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_util.hpp"
#include "sogmm/format.hpp"

namespace {

// What the reader accepts has valid UTF-8 strings (it rejects the others,
// regressions/verify/json_dump_invalid_utf8), so its dump must succeed.
void dump(const sogmm::Model& m, const sogmm::format::FileInfo* info) {
  bool dumped = false;
  try {
    (void)sogmm::format::to_canonical_json(m, info);
    dumped = true;
  } catch (...) {
  }
  FUZZ_CHECK(dumped);
}

bool bit_equal(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fmt = sogmm::format;
  fmt::ReadOptions strict;
  strict.max_decoded_bytes = 4 << 20;
  fmt::ReadOptions lax = strict;
  lax.verify_checksums = false;

  bool info_ok = false;
  fmt::FileInfo info;
  try {
    info = fmt::read_info(data, size, strict);
    info_ok = true;
    FUZZ_CHECK(info.file_length == size);
    dump(info.metadata, &info);
  } catch (const sogmm::Error&) {
  }

  bool lax_ok = false;
  try {
    const sogmm::Model m = fmt::from_bytes(data, size, lax);
    lax_ok = true;
    dump(m, nullptr);
  } catch (const sogmm::Error&) {
  }

  try {
    const sogmm::Model m = fmt::from_bytes(data, size, strict);
    FUZZ_CHECK(info_ok && info.n_components == m.gmm.size());
    FUZZ_CHECK(lax_ok);
    dump(m, &info);
    fmt::WriteOptions w;
    w.zstd_level = 1;
    const std::vector<std::uint8_t> again = fmt::to_bytes(m, w);
    const sogmm::Model back = fmt::from_bytes(again.data(), again.size());
    FUZZ_CHECK(bit_equal(back.gmm.weights, m.gmm.weights) && bit_equal(back.gmm.means, m.gmm.means) &&
               bit_equal(back.gmm.covariances, m.gmm.covariances));
  } catch (const sogmm::Error&) {
  }
  return 0;
}
