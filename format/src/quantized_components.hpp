// Quantized components (spec/format.md section 5.7, format 1.4, feature bit
// 2): each component stored as small integers in a parametrisation whose
// grids follow the component's own error metric, instead of three float32
// arrays whose entries need ~14 bits each for a thin component.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "sogmm/gmm.hpp"

namespace sogmm::format::detail {

/// The format minor version that defines feature bit 2
/// (kFeatureQuantizedComponents, container.hpp).
inline constexpr std::uint16_t kQuantizedMinor = 4;

/// Codes per component of each array (section 5.7): weights, means, covariances.
inline constexpr std::uint64_t kCodeColumns[3] = {1, 5, 14};

/// The integer codes of a model, component-major (M x kCodeColumns[i]).
struct ComponentCodes {
  std::vector<std::int32_t> arrays[3];
};

/// Codes of `gmm` whose decoding (dequantize) keeps every component within
/// `precision` (> 0) of the original in its own metric, the bound of
/// round_to_precision (core/src/component_precision.hpp): with S = L L^T the
/// original covariance and S', m' the decoded ones,
///   - every eigenvalue of L^-1 S' L^-T lies in [1 - precision, 1 + precision];
///   - |L^-1 (m' - m)| <= precision (the mean moves by at most `precision`
///     standard deviations);
///   - each weight is within a factor 1 +- 2^-4 of the original before the
///     decoder renormalises the weights to sum 1.
/// Every component is checked on its decoded float32 values before the codes
/// are returned; std::nullopt when one cannot be (a zero or subnormal weight,
/// a covariance too ill-conditioned for the grids, codes beyond int32): the
/// writer then stores floats. A model decoded from such codes gets those
/// codes back (but for a few with equal eigenvalues, spec 5.7), so
/// saving it again does not move it.
std::optional<ComponentCodes> quantize(const Gmm& gmm, double precision);

/// The model of section 5.7's formulas: fills `out` (resized to M
/// components; full symmetric covariances) from `codes`. Throws
/// FormatError(InvalidData, "bad_quantization") naming the component and the
/// code when a code is out of its range; every covariance is then symmetric
/// positive definite in exact arithmetic, and finite.
void dequantize(const ComponentCodes& codes, std::uint64_t m, Gmm& out);

/// zigzag(v) = 2v for v >= 0, -2v - 1 for v < 0, as stored (section 5.7).
inline std::uint32_t zigzag(std::int32_t v) {
  return (static_cast<std::uint32_t>(v) << 1) ^ static_cast<std::uint32_t>(-(static_cast<std::uint32_t>(v) >> 31));
}
inline std::int32_t unzigzag(std::uint32_t u) {
  return static_cast<std::int32_t>((u >> 1) ^ (~(u & 1) + 1));
}

}  // namespace sogmm::format::detail
