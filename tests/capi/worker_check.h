/* Failure counting inside test worker threads: a failed WCHECK in a worker
 * counts against that worker (the main thread sums the counts after join)
 * and prints the thread, the place and the thread's last C API error. */
#ifndef SOGMM_TEST_WORKER_CHECK_H
#define SOGMM_TEST_WORKER_CHECK_H

#include <stdio.h>

#include "sogmm/sogmm.h"

typedef struct {
  int index;    /* worker number, for messages */
  int failures; /* failed WCHECKs of this worker */
} worker_arg;

/* Needs a `worker_arg* arg` in scope. */
#define WCHECK(cond)                                                                  \
  do {                                                                                \
    if (!(cond)) {                                                                    \
      ++arg->failures;                                                                \
      fprintf(stderr, "thread %d: %s:%d: %s (last error: %s)\n", arg->index, __FILE__, \
              __LINE__, #cond, sogmm_last_error());                                   \
    }                                                                                 \
  } while (0)

#endif
