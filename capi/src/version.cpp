// Runtime version queries.
#include "internal.hpp"

#ifndef SOGMM_CAPI_VERSION_STRING
#define SOGMM_CAPI_VERSION_STRING SOGMM_VERSION_STRING
#endif

extern "C" {

SOGMM_API uint32_t sogmm_version_number(void) { return SOGMM_VERSION_NUMBER; }
SOGMM_API const char* sogmm_version_string(void) { return SOGMM_CAPI_VERSION_STRING; }
SOGMM_API uint32_t sogmm_abi_version(void) { return SOGMM_ABI_VERSION; }

}  // extern "C"
