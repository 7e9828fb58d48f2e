// Metadata strings of a whole model against the rule of
// sogmm/metadata_string.hpp (spec/format.md section 4.4).
#pragma once

#include "sogmm/error.hpp"
#include "sogmm/model.hpp"

namespace sogmm::format::detail {

/// Throws FormatError(code, "bad_metadata") naming the first string of the
/// model's metadata (producer name and version, key/value keys and values)
/// that is not valid UTF-8 or contains NUL.
void check_strings(const Model& model, ErrorCode code);

}  // namespace sogmm::format::detail
