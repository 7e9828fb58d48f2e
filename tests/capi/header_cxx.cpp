// Compiles the public header as C++ (-Wall -Wextra -pedantic -Werror) and
// checks that the declarations have C linkage and fixed-width types.
#include "sogmm/sogmm.h"

#include <cstdint>
#include <type_traits>

static_assert(std::is_same<sogmm_status, std::int32_t>::value, "sogmm_status is int32_t");
static_assert(std::is_same<sogmm_key, std::int32_t>::value, "sogmm_key is int32_t");
static_assert(SOGMM_VERSION_NUMBER == SOGMM_VERSION_MAJOR * 10000 + SOGMM_VERSION_MINOR * 100 +
                                          SOGMM_VERSION_PATCH,
              "version number");

extern "C" typedef sogmm_status c_fit_fn(sogmm_model**, const float*, size_t, const sogmm_model*,
                                          const sogmm_options*);

int main() {
  c_fit_fn* fit = &sogmm_fit_points_f32;  // C linkage function type
  (void)fit;
  sogmm_buffer_free(nullptr);
  return sogmm_version_number() == SOGMM_VERSION_NUMBER ? 0 : 1;
}
