// Helpers shared by the format tests: synthetic models and an independent
// bit-by-bit CRC-32C.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "sogmm/model.hpp"

namespace sogmm::test {

/// A valid model with m components: random weights (normalised), means in a
/// 3 m box with gray in [0, 1], SPD covariances A A^T + eps I built in double
/// and rounded symmetrically to float. Fully populated metadata when `full`.
Model synthetic_model(std::size_t m, std::uint32_t seed, bool full_metadata = true);

/// Bitwise CRC-32C, written independently of the library's table version.
std::uint32_t crc32c_bitwise(const std::uint8_t* p, std::size_t n);

/// Reads a little-endian integer.
template <typename T>
T le(const std::vector<std::uint8_t>& b, std::size_t off) {
  T v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<T>(b[off + i]) << (8 * i));
  return v;
}

/// True when both models hold bit-identical arrays and equal metadata.
bool bit_equal(const Model& a, const Model& b);

/// What a reader returns for a FULL covariance whose entries (i, j) and
/// (j, i) are the neighbouring floats a and b (spec/format.md 5.1): their
/// mean is a tie, rounded to the one with an even significand. From the bits,
/// not from the reader's arithmetic.
float symmetric_tie(float a, float b);

/// A fresh empty directory /tmp/PREFIX-XXXXXX for files a test writes.
/// Throws std::runtime_error when it cannot be made.
std::string make_scratch_dir(const std::string& prefix);
/// Names of the entries of a directory (without "." and "..").
std::vector<std::string> list_dir(const std::string& dir);
/// Makes `dir` writable again, removes its files, then the directory itself.
void remove_scratch_dir(const std::string& dir);
/// The whole content of a file (empty if it cannot be read).
std::vector<std::uint8_t> read_file_bytes(const std::string& path);

}  // namespace sogmm::test
