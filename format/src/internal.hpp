// Internal hooks of the format module, for tests and the conformance-vector
// generator only. Not installed, not part of the public API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "container.hpp"
#include "packed_key_values.hpp"
#include "source.hpp"
#include "sogmm/format.hpp"

namespace sogmm::format::detail {

/// Deliberate deviations from a normal write, used to produce the invalid and
/// "future" conformance vectors. A default Tweaks is a normal write.
struct Tweaks {
  bool validate = true;                 ///< false: write even an invalid model
  std::uint16_t major = kFormatMajor;   ///< header version
  std::uint16_t minor = kFormatMinor;
  std::uint64_t features_required = 0;
  std::uint64_t features_used = 0;
  std::optional<std::uint64_t> n_components;  ///< declared M (default: the model's)
  bool lengths_follow_declared_m = false;     ///< decoded_length fields computed from declared M
  bool force_full_layout = false;             ///< store covariances as FULL even when symmetric
  std::uint32_t covariance_crc_xor = 0;       ///< corrupts the declared covariance CRC
  std::optional<std::uint8_t> means_codec;    ///< overrides the declared codec of the means
  std::optional<std::uint64_t> means_offset;  ///< overrides the declared offset of the means
  std::optional<std::uint32_t> dims;          ///< overrides dims (written even when 4)
  std::optional<std::vector<std::string>> axis_units;  ///< overrides the axis units
  /// Whether the axis lists are written: absent, the writer's rule (omitted
  /// in files with feature bit 2 or 3, which are then format 1.5; spec/format.md
  /// section 7); true, written as formats 1.0 to 1.4 wrote them (the
  /// conformance vectors of those versions, the tests that such files read).
  std::optional<bool> axis_lists;
  std::optional<std::vector<double>> raw_pose;         ///< pose vector written as is (any length)
  bool unknown_optional_fields = false;  ///< appends fields with ids unknown to format 1.0
  bool share_strings = false;  ///< key/value strings stored once and shared (FlatBuffers CreateSharedString)
  /// Key/values packed in the body (spec/format.md 2.5.1; the caller sets
  /// features bit 1): the metadata keeps only the entry that locates them.
  bool pack_key_values = false;
  /// A map (a model with a `map_frames` entry) written with its frame lines
  /// as the binary record (format 1.3, 1.5 without the axis lists;
  /// spec/format.md 2.3.2); false: as text,
  /// as format 1.0 wrote it (for the tests that old map files still read).
  bool compact_maps = true;
  /// The frame record's locating value and stored bytes written as given
  /// (hostile records for the tests of step 21 and the conformance vectors).
  std::optional<std::string> frame_record_entry;
  std::optional<std::vector<std::uint8_t>> frame_record_stored;
};

/// The format version of a map file with the frame record (bits 1 and 3).
inline constexpr std::uint16_t kMinorFrameRecord = 3;
/// The format version from which a file with feature bit 2 or 3 may omit the
/// fixed axis lists (spec/format.md section 7).
inline constexpr std::uint16_t kMinorAxisListsOptional = 5;
/// The feature bits whose files omit the axis lists: a file any reader of it
/// reads identically without them (every 1.x reader reads absent lists as the
/// fixed ones, spec/format.md section 4.2).
inline constexpr std::uint64_t kFeaturesWithoutAxisLists = 4 | 8;

/// The version and feature bits of a map delta (spec/format.md sections 2.5
/// and 2.5.1): written as format 1.2 with features_required bit 0 and its
/// key/values packed (bit 1), checked as a delta.
inline Tweaks map_delta_tweaks() {
  Tweaks t;
  t.minor = 2;
  t.features_required = kFeatureMapDelta | kFeaturePackedKeyValues;
  t.pack_key_values = true;
  return t;
}

/// A map delta as format 1.1 wrote it (key/values in the metadata), for the
/// tests that old deltas still read.
inline Tweaks map_delta_tweaks_1_1() {
  Tweaks t;
  t.minor = 1;
  t.features_required = kFeatureMapDelta;
  return t;
}

/// The reading procedure on `src`; *info (if not null) as load(). `delta`:
/// the file must be a map delta, read by the delta rules (section 2.5).
Model read_model(const Source& src, const ReadOptions& options, FileInfo* info, bool delta);

/// to_bytes() with tweaks.
std::vector<std::uint8_t> encode(const Model& model, const WriteOptions& options, const Tweaks& tweaks);

/// Recomputes the metadata CRC in the header after the metadata was patched.
void refresh_metadata_crc(std::vector<std::uint8_t>& file);

/// In a file written with float64 = true, compress = false: sets element
/// `index` of array `which` (kWeights, kMeans, kCovariances of schema.hpp,
/// canonical order) to `value` and updates that array's CRC-32C and the
/// metadata CRC, so the file holds a binary64 value no float32 model has.
/// Throws std::logic_error for any other file.
void patch_f64_value(std::vector<std::uint8_t>& file, int which, std::uint64_t index, double value);

/// Fault injection for save(): when set, called at each stage of the atomic
/// write; returning true makes that stage fail as if the system call had.
enum class SaveStage { Open, WriteHalf, Fsync, Rename };
using SaveFaultHook = bool (*)(SaveStage stage);
void set_save_fault_hook(SaveFaultHook hook);

/// Receives the bytes of a file in order, a chunk at a time.
using ByteSink = std::function<void(const std::uint8_t* data, std::size_t size)>;

/// Writes a file of `size` bytes atomically (what save() uses): `produce`
/// hands the bytes, in order, to the sink it is given, which writes them to a
/// temporary file in the directory of the final target of `path` (symbolic
/// links are followed, so a link keeps pointing at the new model), created
/// with the target's permission bits (set-user-ID, set-group-ID and sticky
/// bits dropped) and a name that fits NAME_MAX; the temporary file is fsync'ed
/// and renamed over the target. Throws Error(Io) and leaves the previous file
/// and no temporary file on failure, also when `produce` throws.
void atomic_write(const std::string& path, std::uint64_t size, const std::function<void(const ByteSink&)>& produce);

}  // namespace sogmm::format::detail
