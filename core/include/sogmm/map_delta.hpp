// Map deltas (issue 33): what changed in a map between two revisions, so that
// a receiver that applies them in order holds a copy bitwise equal to the
// sender's map (weights, means, covariances, support size, frame
// provenance) without ever receiving the whole map again.
//
// Why operations and not "components added and removed": every flush merges
// by support size (merge() of sogmm/inference.hpp), which rescales the weight
// of every component already in the map. Sending every weight at every flush
// would cost 4 bytes per component per flush; sending the rescale instead
// costs nothing, and the receiver gets the same float32 weights bit for bit
// by running the same IEEE arithmetic (one double multiply or divide per
// weight and a cast; no reassociation) on the same inputs. A digest of the
// sender's map after the delta catches any receiver that would still end
// elsewhere: it refuses instead of diverging silently.
//
// Components have no identity beyond their position in the map: every
// operation names positions in the map as the previous operation left it,
// which the receiver, holding the same map, resolves the same way.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/model.hpp"

namespace sogmm {

/// One step of a delta. Explicit components (MapDelta::model.gmm) are taken
/// in order by the steps that carry them (Merge: `count`, Set: one per id).
struct DeltaOp {
  enum class Kind {
    /// map = merge(map, batch) (or batch when the map is empty): the next
    /// `count` explicit components with support size `support` are a batch
    /// fitted by the sender; every map weight is rescaled by support.
    Merge,
    /// map = the map without components `ids` (ascending); the others keep
    /// their mass in points: weights renormalised, support scaled (a revisit
    /// refit drops what it replaces).
    Remove,
    /// component ids[i] = the next explicit component (weight, mean and
    /// covariance as carried): a component fusion changed in place.
    Set,
    /// components `ids` (ascending) erased, nothing renormalised: new
    /// components fusion merged into older ones (their mass moved there).
    Drop,
  };
  Kind kind = Kind::Merge;
  std::uint64_t count = 0;          ///< Merge: explicit components of the batch
  std::uint64_t support = 0;        ///< Merge: the batch's support size
  std::vector<std::uint64_t> ids;   ///< Remove, Set, Drop: map positions
};

/// A map's change from revision base_revision to revision (both of the map
/// named map_id).
struct MapDelta {
  std::string map_id;               ///< 32 lowercase hex digits (Map::id())
  std::uint64_t base_revision = 0;  ///< the receiver must be at this revision
  std::uint64_t revision = 0;       ///< the receiver's revision after it
  /// The receiver's frame count at base_revision, and the first frame line
  /// the delta carries (frames_before - 1, or 0): the last frame line a
  /// receiver holds may still change (a flush records its component count).
  std::uint64_t frames_before = 0;
  std::uint64_t frames_from = 0;
  /// Provenance lines of frames frames_from.. (the kMapFramesKey format).
  std::string frames;
  std::vector<DeltaOp> ops;
  /// Explicit components in gmm (any positive weights; support_size is the
  /// map's after the delta); the rest is the map model's metadata after the
  /// delta (fit record, camera, key_values), which replaces the receiver's.
  Model model;
  /// FNV-1a 64 of the map after the delta (map_digest of sogmm/map_delta.hpp).
  std::uint64_t digest = 0;
};

/// Metadata keys of a delta stored as a model (spec/format.md section 2.5).
inline constexpr const char* kDeltaMapIdKey = "delta_map_id";
inline constexpr const char* kDeltaBaseRevisionKey = "delta_base_revision";
inline constexpr const char* kDeltaRevisionKey = "delta_revision";
inline constexpr const char* kDeltaFramesBeforeKey = "delta_frames_before";
inline constexpr const char* kDeltaFramesFromKey = "delta_frames_from";
inline constexpr const char* kDeltaFramesKey = "delta_frames";
inline constexpr const char* kDeltaOpsKey = "delta_ops";
inline constexpr const char* kDeltaDigestKey = "delta_digest";

/// Keys a saved map carries so that a base map and the deltas after it
/// agree (spec/format.md section 2.3).
inline constexpr const char* kMapIdKey = "map_id";
inline constexpr const char* kMapRevisionKey = "map_revision";

/// The delta as a model whose key_values add the kDelta* keys (the form the
/// file format stores; spec/format.md section 2.5).
Model delta_to_model(const MapDelta& delta);

/// The inverse of delta_to_model. Error(Format) naming the key and the
/// problem for a missing or malformed delta key (a revision below the base,
/// an op line that does not parse, a count of explicit components that does
/// not match the components carried, frames_from after frames_before).
MapDelta delta_from_model(const Model& model);

/// FNV-1a 64 over the map's float32 weights, means and covariances (IEEE
/// bits, little-endian), its support size (u64 little-endian) and its frame
/// provenance text: equal digests mean a bitwise equal map, to 2^-64.
std::uint64_t map_digest(const Gmm& gmm, const std::string& frames_text);

}  // namespace sogmm
