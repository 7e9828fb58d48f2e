/* Compiles the public header as strict C99 (-std=c99 -Wall -Wextra -pedantic
 * -Werror) and checks the compile-time constants the header promises. */
#include "sogmm/sogmm.h"
#include "sogmm/sogmm.h" /* include guard */

typedef char check_status_width[sizeof(sogmm_status) == 4 ? 1 : -1];
typedef char check_key_width[sizeof(sogmm_key) == 4 ? 1 : -1];
typedef char check_version[SOGMM_VERSION_NUMBER ==
                                   SOGMM_VERSION_MAJOR * 10000 + SOGMM_VERSION_MINOR * 100 +
                                       SOGMM_VERSION_PATCH
                               ? 1
                               : -1];

int main(void) {
  check_status_width a;
  check_key_width b;
  check_version c;
  sogmm_model* m = 0;
  (void)a;
  (void)b;
  (void)c;
  sogmm_model_free(m); /* links: the symbols resolve */
  return (SOGMM_OK == 0 && SOGMM_E_NULL_ARG < 0 && sogmm_abi_version() == SOGMM_ABI_VERSION) ? 0 : 1;
}
