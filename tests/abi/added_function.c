/* Shim: one function more than the ABI baseline, a compatible addition. */
#include <sogmm/sogmm.h>

SOGMM_API int32_t sogmm_abi_test_added(void);
SOGMM_API int32_t sogmm_abi_test_added(void) { return 1; }
