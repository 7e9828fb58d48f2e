// Runs part of a test in a child process, for code that may abort, exhaust
// memory or hang on a broken build: the test then fails, but the test run
// (and the rest of the executable) carries on.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace sogmm::test {

/// Runs `body` in a child process and expects it to return "" (success);
/// otherwise the test fails showing what `body` returned (its reason) or how
/// the child ended (a signal: crash, abort, or the `guard_seconds` alarm that
/// stops a hang). The child is a fresh copy of the test executable (gtest's
/// "threadsafe" death-test style): OpenMP's thread pool does not survive a
/// plain fork. Use at most once per test.
template <typename Body>
void expect_child_succeeds(const Body& body, unsigned guard_seconds) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        ::alarm(guard_seconds);
        const std::string problem = body();
        std::fprintf(stderr, "%s\n", problem.c_str());
        std::exit(problem.empty() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace sogmm::test
