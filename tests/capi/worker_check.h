/* Failure counting inside test worker threads: a failed WCHECK in a worker
 * counts against that worker (the main thread sums the counts after join)
 * and prints the thread, the place and the thread's last C API error. */
#ifndef SOGMM_TEST_WORKER_CHECK_H
#define SOGMM_TEST_WORKER_CHECK_H

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

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

/* Runs worker(&args[i]) on n threads at once (args[i].index = i, failures
 * reset to 0) and joins them; returns the sum of their failures, or -1 after
 * a message if a thread could not be started (the started ones are joined). */
static int run_workers(void* (*worker)(void*), worker_arg* args, int n) {
  pthread_t* threads = (pthread_t*)malloc(sizeof(pthread_t) * (size_t)n);
  int t, started = 0, failures = 0;
  if (threads == NULL) {
    fprintf(stderr, "run_workers: out of memory\n");
    return -1;
  }
  for (t = 0; t < n; ++t) {
    args[t].index = t;
    args[t].failures = 0;
    if (pthread_create(&threads[t], NULL, worker, &args[t]) != 0) {
      fprintf(stderr, "pthread_create failed\n");
      break;
    }
    ++started;
  }
  for (t = 0; t < started; ++t) {
    pthread_join(threads[t], NULL);
    failures += args[t].failures;
  }
  free(threads);
  return started == n ? failures : -1;
}

#endif
