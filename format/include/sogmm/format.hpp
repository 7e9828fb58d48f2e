// The .sogmm file format: reading, writing and verifying SOGMM models.
//
// The normative description of the bytes is spec/format.md; the metadata
// schema is spec/sogmm.fbs. This header is the C++ face of it.
//
// Errors: every function reports a problem by throwing sogmm::Error (in fact
// a sogmm::format::FormatError, which adds a stable reason identifier from
// spec/format.md section 9):
//   ErrorCode::Format       structure, version, feature, encoding or checksum problem
//   ErrorCode::Limit        a declared size is over ReadOptions::max_decoded_bytes
//   ErrorCode::InvalidData  M = 0, array lengths that disagree with M, bad pose
//   ErrorCode::Numeric      NaN/Inf, weights not summing to 1, non-symmetric or
//                           non-positive-definite covariance
//   ErrorCode::Io           a file cannot be opened, read or written
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/error.hpp"
#include "sogmm/file_options.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format {

/// Format version this library writes for a model of float arrays. The
/// newest it knows is 1.5: a map (spec/format.md 2.3.2) and a file with
/// quantized components (WriteOptions::component_precision > 0, section 5.7)
/// are written as 1.5, which leaves out the fixed axis lists (section 7; 1.3
/// and 1.4 wrote them), a map delta as 1.2.
inline constexpr std::uint16_t kFormatMajor = 1;
inline constexpr std::uint16_t kFormatMinor = 0;

// WriteOptions, ReadOptions and kDefaultMaxDecodedBytes are declared in
// sogmm/file_options.hpp (core), where the option registry reaches them.

/// A sogmm::Error raised by this module, with the stable reason identifier
/// that spec/format.md section 9 assigns to each rejection ("bad_magic",
/// "truncated", "checksum_mismatch", ...). what() starts with the reason.
class FormatError : public Error {
 public:
  FormatError(ErrorCode code, std::string reason, const std::string& detail)
      : Error(code, reason + ": " + detail), reason_(std::move(reason)) {}
  /// The reason identifier, e.g. "not_spd".
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string reason_;
};

/// Encodes a model into the bytes of a .sogmm file. Refuses (throws
/// Error(InvalidData/Numeric), nothing written) a model that a reader would
/// reject, metadata strings that are not valid UTF-8 or contain NUL included.
/// An empty producer_version is written as sogmm::version_string().
/// Covariances are stored packed (upper triangle) when every matrix is
/// bit-exactly symmetric, else in full, so the round trip is bit-exact;
/// with options.component_precision > 0 the components are stored as integer
/// codes instead (feature bit 2) and read back within that precision's bound
/// (sogmm/file_options.hpp). A file with feature bit 2 or 3 (quantized
/// components, a map's frame record) leaves out the fixed axis lists and is
/// format 1.5 (spec/format.md section 7); any other is format 1.0.
std::vector<std::uint8_t> to_bytes(const Model& model, const WriteOptions& options = {});

/// Decodes and fully verifies the bytes of a .sogmm file.
Model from_bytes(const void* data, std::size_t size, const ReadOptions& options = {});

/// Writes a .sogmm file atomically: a temporary file in the same directory is
/// written, fsync'ed and renamed over `path`. On failure the previous file (if
/// any) is untouched and no temporary file is left; throws Error(Io).
void save(const std::string& path, const Model& model, const WriteOptions& options = {});

/// Writes any file (not only a model: the tools' CSV, SVG, PLY, PNG and
/// trajectories) by the one mechanism save() uses: `size` bytes from `data`
/// go to a temporary file next to the final target of `path` (a symbolic link
/// is written through, so it keeps pointing at the new file), fsync'ed and
/// renamed over it with the replaced file's permission bits. Refuses a target
/// that exists and is not a regular file (a device, a FIFO, a directory): it is
/// never replaced. On failure the previous file is untouched and no temporary
/// file is left; throws Error(Io) naming the file.
void write_file(const std::string& path, const void* data, std::size_t size);

/// Reads and fully verifies a .sogmm file. Throws Error(Io) when it cannot be
/// read or is not a regular file (a FIFO, a device or a directory is refused
/// at once, never waited on). The file is read piecewise: header first, then
/// the metadata block, then each array; memory as in spec/format.md section 8.
Model load(const std::string& path, const ReadOptions& options = {});

/// How one array is encoded in a file.
struct ArrayInfo {
  std::string dtype;          ///< "f32" or "f64"
  std::string order;          ///< "component_major" or "column_major"
  std::string filter;         ///< "none" or "byte_stream_split"
  std::string codec;          ///< "none" or "zstd"
  std::uint64_t offset = 0;   ///< file offset of the stored bytes
  std::uint64_t stored_length = 0;
  std::uint64_t decoded_length = 0;
  std::uint32_t crc32c = 0;   ///< declared CRC-32C of the decoded bytes
};

/// Everything about a file except the bulk arrays: obtained by reading and
/// verifying only the header and the metadata block (no decompression).
struct FileInfo {
  std::uint16_t format_major = 0;
  std::uint16_t format_minor = 0;
  std::uint64_t file_length = 0;
  std::uint64_t metadata_length = 0;
  std::uint64_t features_required = 0;
  std::uint64_t features_used = 0;
  std::string covariance_layout;  ///< "upper_packed" or "full"
  std::uint64_t n_components = 0;
  ArrayInfo weights, means, covariances;
  /// The metadata as a Model whose Gmm holds no arrays (only support_size).
  Model metadata;
};

/// Reads and verifies the header and the metadata block of a whole file in
/// memory (steps 1 to 12 of spec/format.md section 9: everything except
/// decoding the arrays and checking their values). No decompression. Also
/// describes a map delta (features_required bit 0, spec/format.md 2.5),
/// which load() and from_bytes() refuse.
FileInfo read_info(const void* data, std::size_t size, const ReadOptions& options = {});

/// read_info() on a file, reading only its header, metadata block and last 4
/// bytes. Throws Error(Io) when the file cannot be read.
FileInfo read_info_file(const std::string& path, const ReadOptions& options = {});

/// load() that also returns the file information in *info (not null), whose
/// `metadata` member is left default-constructed: the returned model holds
/// the metadata. One read, for tools that show both.
Model load(const std::string& path, const ReadOptions& options, FileInfo* info);

/// Canonical JSON dump of a model and its file information (spec/format.md
/// section 10): fixed key order, 2-space indentation, numbers written so that
/// parsing them gives back the exact value. `info` may be null (model only).
/// Throws Error(InvalidData) for a string that breaks the metadata string
/// rule of sogmm/metadata_string.hpp (a model read from a file never has one).
std::string to_canonical_json(const Model& model, const FileInfo* info = nullptr);

}  // namespace sogmm::format
