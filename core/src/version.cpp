#include "sogmm/model.hpp"

namespace sogmm {
const char* version_string() { return SOGMM_VERSION_STRING; }
}  // namespace sogmm
