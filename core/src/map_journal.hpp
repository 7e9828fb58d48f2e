// The record of a map's changes that deltas are cut from (issue 33;
// sogmm/map_delta.hpp). Never installed.
//
// Every public call that changes a map (an insert, a flush, a delta applied)
// is one revision: its steps collect in the open entry while it runs and
// become one entry when it succeeds; a failed call leaves the journal as it
// was (the map itself is undone by the caller, see Map::insert_points).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/gmm.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/model.hpp"

namespace sogmm::detail {

/// The change of one revision (or of several, for a receiver that applied a
/// delta spanning several: it can relay it whole, not cut inside it).
struct JournalEntry {
  std::uint64_t revision_before = 0;
  std::uint64_t revision_after = 0;
  std::uint64_t frames_before = 0;  ///< the map's frame count at revision_before
  std::vector<DeltaOp> ops;
  Gmm components;                   ///< explicit components of the ops, in order
};

struct Journal {
  std::string map_id;               ///< 32 hex digits, random at construction
  std::uint64_t revision = 0;       ///< the map's revision (Map::revision)
  std::uint64_t first_revision = 0; ///< deltas can start here or later (a loaded map starts later)
  std::vector<JournalEntry> entries;
  // The entry of the call under way.
  int depth = 0;
  std::vector<DeltaOp> open_ops;
  Gmm open_components;
  std::uint64_t open_frames_before = 0;

  /// Appends the explicit components [first, first + n) of `gmm`.
  void add_components(const Gmm& gmm, std::size_t first, std::size_t n);
  void merge(const Gmm& batch);
  void remove(const std::vector<std::size_t>& ids);
  /// Set steps for components `ids` of `gmm` (their values after the change).
  void set(const Gmm& gmm, const std::vector<std::size_t>& ids);
  void drop(const std::vector<std::size_t>& ids);
};

/// Components [first, end) of `gmm` (support size 0).
Gmm tail(const Gmm& gmm, std::size_t first);

/// The positions (first + j, ascending) of the components of `appended`
/// (what a flush appended at `first`, before fusion) that fusion removed:
/// `after`'s components from `first` on are the kept ones, unchanged and in
/// order, so a greedy match of their bytes finds them (two bitwise equal
/// components are interchangeable: either choice gives the same map).
std::vector<std::size_t> dropped_positions(const Gmm& appended, const Gmm& after, std::size_t first);

/// Adds the keys kMapIdKey and kMapRevisionKey of the journal to a saved map.
void write_identity(Model& m, const Journal& j);
/// Takes them out of a loaded map into the journal (which then starts at
/// that revision); absent, the journal keeps its fresh id at revision 0.
/// Malformed -> Error(Format).
void read_identity(Model& m, Journal& j);

/// A fresh random map id (32 lowercase hex digits).
std::string new_map_id();

/// Opens the call's journal entry; nested calls (a flush inside an insert)
/// join the outer one. commit() closes it as one revision when the call
/// changed something (steps recorded, or the frame count moved); destroyed
/// without commit, the outermost scope discards what was recorded.
class JournalScope {
 public:
  JournalScope(Journal& journal, std::size_t n_frames);
  ~JournalScope();
  JournalScope(const JournalScope&) = delete;
  JournalScope& operator=(const JournalScope&) = delete;
  void commit(std::size_t n_frames);

 private:
  Journal& j_;
  bool done_ = false;
};

}  // namespace sogmm::detail
