// Mapping between sogmm::Model and the FlatBuffers metadata block
// (spec/sogmm.fbs), and the metadata checks (spec/format.md section 9, steps 9-16).
#pragma once

#include <cstdint>
#include <vector>

#include <flatbuffers/detached_buffer.h>

#include "container.hpp"
#include "internal.hpp"
#include "quantized_components.hpp"

namespace sogmm::format::detail {

/// One array's metadata record (the fields of table Array).
struct ArrayRecord {
  std::uint8_t dtype = 0, order = 0, filter = 0, codec = 0;
  std::uint64_t offset = 0, stored_length = 0, decoded_length = 0;
  std::uint32_t crc32c = 0;
};

/// Index of the arrays in the records below.
enum { kWeights = 0, kMeans = 1, kCovariances = 2 };

/// Most tables a reader verifies in one metadata block (spec/format.md
/// section 4.3); a writer never emits more.
inline constexpr std::uint32_t kMaxMetadataTables = 100000;

/// Builds the metadata FlatBuffer of `model` (arrays excluded) with the given
/// array records, declared M and covariance layout. Every array's offset field
/// is written (a record's offset is never 0), so set_array_offsets() can fill
/// in the real offsets once the block's length is known. `size_hint` (an upper
/// bound of the result) sizes the builder so that it never grows by copying.
flatbuffers::DetachedBuffer build_metadata(const Model& model, const ArrayRecord (&arrays)[3], std::uint64_t n_declared,
                                           bool packed, const Tweaks& tweaks, std::size_t size_hint);

/// Overwrites the offset of array i (0: weights, 1: means, 2: covariances)
/// with offsets[i] in a block from build_metadata(), for each i with
/// patch[i] set.
void set_array_offsets(std::uint8_t* metadata, const std::uint64_t (&offsets)[3], const bool (&patch)[3]);

/// The metadata once verified.
struct ParsedMetadata {
  FileInfo info;
  ArrayRecord arrays[3];
  bool packed = true;
  bool quantized = false;  ///< features_required bit 2: the arrays hold codes (section 5.7)
};

/// Number of bytes the codec of array `which` yields: its decoded_length, or
/// for quantized codes M x kCodeColumns[which] x 4 (at most 4/3 of it, so
/// below 2^64 once step 14 has passed).
inline std::uint64_t filtered_length(const ParsedMetadata& p, int which) {
  return p.quantized ? p.arrays[which].decoded_length / (which == kWeights ? 1 : which == kMeans ? 4 : 10) *
                           kCodeColumns[which]
                     : p.arrays[which].decoded_length;
}

/// Steps 9-16: verifies the FlatBuffer, the features, the metadata values
/// (strings included), the encodings, M, the declared lengths, the size cap
/// and the buffer layout; then decodes the metadata. `metadata` holds the
/// header.metadata_length bytes of the block and is 8-byte aligned (so every
/// FlatBuffers scalar read is aligned).
/// `known_features`: the features_required bits this reading accepts (a map
/// delta's reader adds kFeatureMapDelta, which also allows M = 0).
ParsedMetadata parse_metadata(const std::uint8_t* metadata, const Header& header, const ReadOptions& options,
                              std::uint64_t known_features = kKnownFeatures);

/// Number of columns C of array `which` (1, 4, 10 or 16).
inline std::uint64_t columns(int which, bool packed) {
  return which == kWeights ? 1 : which == kMeans ? 4 : (packed ? 10 : 16);
}

/// The writer's size cap: throws FormatError(Limit, "limit") when the three
/// arrays of an M-component model (covariances packed or full, float32 or
/// float64 elements) decode to more than `cap` bytes, the message naming
/// both sizes and how to raise the cap. Reads no array: M is enough.
void check_decoded_size(std::uint64_t m, bool packed, bool float64, std::uint64_t cap);

}  // namespace sogmm::format::detail
