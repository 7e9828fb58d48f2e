// Tables of points in and columns of results out, for `sogmm query`: a
// planner's points come as text (CSV) or NumPy arrays, and its answers go
// back the same way.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace sogmm::tools {

/// Reads n points (x, y, z) from `path` into rows of 3 floats:
/// - `.npy`: a 2-D array (C or Fortran order) of little-endian float32 or
///   float64 with at least 3 columns (the first 3 are used), NumPy format
///   1.0-3.0;
/// - anything else: text, one point per line, the first three numbers
///   separated by commas, spaces or tabs; empty lines and lines starting
///   with '#' are skipped, and so is a first line that does not start with
///   a number (a header).
/// At most kMaxPoints points. Errors name the file and the line or field:
/// Error(Io) unreadable, Error(Format) malformed, Error(InvalidData) a
/// non-finite coordinate or no point, Error(Limit) too many points.
std::vector<float> read_points(const std::string& path);

/// Columns of a result table, each n values.
struct Column {
  std::string name;
  std::vector<double> values;
};

/// Writes the columns atomically (write_file_atomic): `.npy` as one float64
/// (n, columns) array in the given order, anything else as CSV with a
/// header line of the names and values printed to round-trip (%.17g).
void write_columns(const std::string& path, const std::vector<Column>& columns);

}  // namespace sogmm::tools
