// Map deltas as files of a folder: `sogmm map --deltas DIR` writes them,
// `sogmm apply-deltas DIR` reads them (issue 33; spec/format.md 2.5).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sogmm/map.hpp"

namespace sogmm::tools {

/// The name of the delta that ends at `revision`: "delta-" and the revision
/// in 12 digits, so that names sort in revision order.
std::string delta_file_name(std::uint64_t revision);

/// Writes one delta file per call, from the revision the previous one ended
/// at (0 for the first: the map is new) to the map's current one, into a
/// folder (created when missing); nothing when no folder was given or the
/// map did not change. Atomic writes.
class DeltaWriter {
 public:
  explicit DeltaWriter(std::string dir);
  void write(const Map& map);
  std::uint64_t count() const { return count_; }
  std::uint64_t bytes() const { return bytes_; }

 private:
  std::string dir_;
  std::uint64_t since_ = 0, count_ = 0, bytes_ = 0;
};

/// The delta files of a folder (names delta-*.sogmm), sorted by name.
/// Error(Io) when the folder cannot be read; Error(InvalidArgument) when it
/// holds none.
std::vector<std::string> delta_files(const std::string& dir);

}  // namespace sogmm::tools
