// The thread-count invariance check the EM tests share: a fit is the same
// bits for any number of threads.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "sogmm/fit.hpp"
#include "test_util.hpp"

namespace sogmm_test {

// Fits the points (x, y, z, gray rows) with o at 1, 2 and 3 threads (3 does
// not divide a wave's chunks) and expects the same model, log-likelihood and
// iteration count, bit for bit.
inline void expect_same_fit_for_one_two_three_threads(const std::vector<float>& pts, sogmm::FitOptions o,
                                                      const std::string& what) {
  std::vector<sogmm::FitResult> r;
  for (int threads : {1, 2, 3}) {
    o.em.threads = threads;
    r.push_back(sogmm::fit(sogmm::PointsView{pts.data(), pts.size() / 4}, o));
  }
  for (int i : {1, 2}) {
    EXPECT_TRUE(bit_identical(r[0].gmm, r[i].gmm)) << what << ": 1 vs " << i + 1 << " threads";
    EXPECT_EQ(r[0].em.log_likelihood, r[i].em.log_likelihood) << what;
    EXPECT_EQ(r[0].em.iterations, r[i].em.iterations) << what;
  }
}

}  // namespace sogmm_test
