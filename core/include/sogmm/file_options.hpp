// How .sogmm files are written and read: the settings of the file layer
// (format/), declared in the core so that the one option registry
// (sogmm/options.hpp) covers them with every other setting. The format
// library (sogmm/format.hpp) is what reads them.
#pragma once

#include <cstdint>

namespace sogmm::format {

/// Default cap on the total decoded size of the bulk arrays (1 GiB, enough
/// for about 17 million float32 components). See spec/format.md section 8.
inline constexpr std::uint64_t kDefaultMaxDecodedBytes = std::uint64_t{1} << 30;

/// How a model is encoded.
struct WriteOptions {
  int zstd_level = 19;   ///< zstd compression level, 1..22 (clamped)
  bool float64 = false;  ///< store arrays as float64 (exact widening of the float32 values)
  bool compress = true;  ///< false: arrays stored raw (no filter, no codec), component-major
  /// > 0: store each component as integer codes (spec/format.md section 5.7,
  /// format 1.5) that move its mean by at most this many of its standard
  /// deviations and its covariance's eigenvalues, in its own frame, by at
  /// most this fraction (the bound of MapOptions::component_precision), and
  /// its weight by a factor of at most 1 +- 2^-4 before the weights are
  /// renormalised; a few bytes per component instead of 60. 0: float arrays,
  /// bit-exact. A model the codes cannot hold (a zero weight, an extreme
  /// condition number) is stored as floats. The codes decode to float32:
  /// float64 has no effect on them. A model read from such a file and saved
  /// again keeps its components bit for bit (the writer finds the codes they
  /// were decoded from), but for a few (1-4% on real maps) whose equal
  /// eigenvalues leave their axes undetermined (spec/format.md 5.7), which
  /// are coded anew within the bound. Range [0, 0.5] (SOGMM_OPT_ARRAY_PRECISION's).
  double component_precision = 0;
  /// Refuse (Error(Limit), nothing written) a model whose arrays would decode
  /// to more bytes than this. The default is the reader's default cap, so a
  /// file a default reader would refuse is never written silently; raise it
  /// together with the readers' ReadOptions::max_decoded_bytes.
  std::uint64_t max_decoded_bytes = kDefaultMaxDecodedBytes;
};

/// How a file is read.
struct ReadOptions {
  /// Reject files whose arrays declare more decoded bytes than this (total
  /// over weights, means and covariances), before allocating anything.
  std::uint64_t max_decoded_bytes = kDefaultMaxDecodedBytes;
  /// Check the CRC-32C of the metadata and of every decoded array.
  bool verify_checksums = true;
};

}  // namespace sogmm::format
