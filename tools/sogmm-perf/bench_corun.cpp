// sogmm-corun: what two threads cost on this machine, whatever the code
// (issue 17's thread-scaling limit). run_perf.py prints it next to the
// core's own losses, so that a two-thread row can be told apart: a loss the
// machine imposes on any code, or one the core's loops add.
//
// 1. Co-run inflation: the same work on one thread alone, then on two
//    threads at once (each its own copy), per-thread median time over the
//    repeats, alternated so that drift hits both alike. Three kinds of work:
//    - alu: independent multiply-add chains in registers (no memory);
//    - l2: sums over a 256 KiB buffer per thread (stays in each core's L2);
//    - dram: sums over a 64 MiB buffer per thread (streams from memory).
//    Two separate cores show ~0% for alu; two hyper-threads of one core, or a
//    host that slows a busy socket, show it there.
// 2. Region cost: opening and closing an empty OpenMP region of two
//    threads (what each of the core's parallel loops pays at least), median
//    microseconds over batches.
//
// Usage: sogmm-corun [--repeat 7]; prints one JSON line.
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>
#include "median.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using sogmm::perf::median;

// Eight independent chains, so the FP units, not latency, bound it.
double alu_work() {
  double a[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  for (long i = 0; i < 40000000; ++i)
    for (double& x : a) x = x * 0.9999999 + 1e-7;
  double s = 0;
  for (double x : a) s += x;
  return s;
}

double sum_work(const std::vector<double>& buffer, int passes) {
  double s[4] = {0, 0, 0, 0};
  for (int p = 0; p < passes; ++p)
    for (std::size_t i = 0; i + 3 < buffer.size(); i += 4)
      for (int j = 0; j < 4; ++j) s[j] += buffer[i + j];
  return s[0] + s[1] + s[2] + s[3];
}

// Per-thread seconds of `work` on a team of `threads`, each member with its
// own buffer of `bytes`; the median member.
template <class Work>
double per_thread_seconds(int threads, std::size_t bytes, const Work& work) {
  std::vector<double> seconds(static_cast<std::size_t>(threads));
  volatile double sink = 0;
#pragma omp parallel num_threads(threads)
  {
    std::vector<double> buffer(bytes / sizeof(double), 1.0);
#pragma omp barrier
    const auto t0 = Clock::now();
    const double r = work(buffer);
    seconds[static_cast<std::size_t>(omp_get_thread_num())] = seconds_since(t0);
#pragma omp critical
    sink = sink + r;
  }
  return median(seconds);
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 7;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
      repeat = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: sogmm-corun [--repeat N]\n");
      return 2;
    }
  }
  if (repeat < 1 || repeat > 1000) {
    std::fprintf(stderr, "sogmm-corun: --repeat must be in [1, 1000]\n");
    return 2;
  }
  struct Kind {
    const char* name;
    std::size_t bytes;
    int passes;
  };
  const Kind kinds[] = {{"alu", 0, 0}, {"l2", 256u << 10, 3000}, {"dram", 64u << 20, 12}};
  std::printf("{");
  for (const Kind& kind : kinds) {
    const auto work = [&](const std::vector<double>& buffer) {
      return kind.bytes == 0 ? alu_work() : sum_work(buffer, kind.passes);
    };
    std::vector<double> one, two;
    for (int r = 0; r < repeat; ++r) {
      one.push_back(per_thread_seconds(1, kind.bytes, work));
      two.push_back(per_thread_seconds(2, kind.bytes, work));
    }
    std::printf("\"%s_1\": %.6f, \"%s_2\": %.6f, ", kind.name, median(one), kind.name, median(two));
  }
  // Empty regions: batches of 2,000, median microseconds per region.
  std::vector<double> region_us;
  for (int r = 0; r < 5 * repeat; ++r) {
    const auto t0 = Clock::now();
    for (int i = 0; i < 2000; ++i) {
#pragma omp parallel num_threads(2)
      {
        (void)omp_get_thread_num();
      }
    }
    region_us.push_back(seconds_since(t0) / 2000 * 1e6);
  }
  std::printf("\"region_us\": %.3f}\n", median(region_us));
  return 0;
}
