// A GoogleTest fixture base for tests that write files: each test gets a fresh
// scratch folder, removed afterwards with whatever the test left in it.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "test_support.hpp"

namespace sogmm::test {

class ScratchDirTest : public ::testing::Test {
 protected:
  /// `prefix` names the folder, /tmp/PREFIX-XXXXXX, so a leftover says which test made it.
  explicit ScratchDirTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override { dir_ = make_scratch_dir(prefix_); }
  void TearDown() override { remove_scratch_dir(dir_); }
  /// The names in the scratch folder (a failed save must leave no temporary file).
  std::vector<std::string> files() const { return list_dir(dir_); }
  static std::vector<std::uint8_t> slurp(const std::string& path) { return read_file_bytes(path); }

  std::string dir_;

 private:
  std::string prefix_;
};

}  // namespace sogmm::test
