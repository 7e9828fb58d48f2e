// C side of the progress callback: the trampoline the library calls, which
// forwards to the exported Go function, and the setters (options, map) that turn a
// cgo.Handle (an integer) into the void* user_data in C, so that no Go code
// converts an integer to a pointer.
#include <stdint.h>

#include "_cgo_export.h"
#include "sogmm/sogmm.h"

static int32_t sogmm_go_trampoline(int32_t stage, uint64_t step, uint64_t total, double log_likelihood,
                                   void* user_data) {
  return sogmmGoProgress(stage, step, total, log_likelihood, (uintptr_t)user_data);
}

sogmm_status sogmm_go_set_progress(sogmm_options* options, uintptr_t handle) {
  return sogmm_options_set_progress(options, sogmm_go_trampoline, (void*)handle);
}

sogmm_status sogmm_go_map_set_progress(sogmm_map* map, uintptr_t handle) {
  return sogmm_map_set_progress(map, sogmm_go_trampoline, (void*)handle);
}
