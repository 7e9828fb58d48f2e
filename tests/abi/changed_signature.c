/* Shim: sogmm_status_string with its parameter widened from sogmm_status
   (int32_t) to int64_t, a signature change that a caller compiled against
   the baseline would misuse. Linked before libsogmm's own objects with
   -z muldefs, so this definition is the exported one. */
#define sogmm_status_string sogmm_status_string_as_declared
#include <sogmm/sogmm.h>
#undef sogmm_status_string

SOGMM_API const char* sogmm_status_string(int64_t status);
SOGMM_API const char* sogmm_status_string(int64_t status) {
  return status == 0 ? "ok" : "error";
}
