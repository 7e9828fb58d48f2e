// Atomic saves: the previous file survives every injected failure and no
// temporary file is left behind.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>


#include <cstdio>
#include <fstream>
#include <string>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "scratch_dir_test.hpp"
#include "test_support.hpp"

namespace sogmm {
namespace {

using format::detail::SaveStage;

class Save : public test::ScratchDirTest {
 protected:
  Save() : ScratchDirTest("sogmm-format-test") {}
  void TearDown() override {
    format::detail::set_save_fault_hook(nullptr);
    ScratchDirTest::TearDown();
  }
};

TEST_F(Save, SaveLoadRoundTrip) {
  const Model m = test::synthetic_model(30, 8);
  const std::string path = dir_ + "/model.sogmm";
  format::save(path, m);
  EXPECT_TRUE(test::bit_equal(format::load(path), m));
  EXPECT_EQ(files(), std::vector<std::string>{"model.sogmm"});
  const format::FileInfo info = format::read_info_file(path);
  EXPECT_EQ(info.n_components, 30u);
  EXPECT_EQ(info.file_length, slurp(path).size());
  // The file is the to_bytes() output.
  const auto bytes = format::to_bytes(m);
  EXPECT_EQ(slurp(path), std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
}

SaveStage g_fail_at;
bool fail_hook(SaveStage s) { return s == g_fail_at; }

TEST_F(Save, InjectedFailuresLeaveThePreviousFileAndNoTemporary) {
  const std::string path = dir_ + "/model.sogmm";
  const Model old_model = test::synthetic_model(3, 1);
  format::save(path, old_model);
  ::chmod(path.c_str(), 0640);
  const std::vector<std::uint8_t> before = slurp(path);
  const Model new_model = test::synthetic_model(40, 2);
  for (SaveStage stage : {SaveStage::Open, SaveStage::WriteHalf, SaveStage::Fsync, SaveStage::Rename}) {
    g_fail_at = stage;
    format::detail::set_save_fault_hook(&fail_hook);
    try {
      format::save(path, new_model);
      ADD_FAILURE() << "save succeeded despite an injected failure at stage " << static_cast<int>(stage);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Io) << e.what();
    }
    format::detail::set_save_fault_hook(nullptr);
    EXPECT_EQ(slurp(path), before) << "stage " << static_cast<int>(stage);
    EXPECT_EQ(files(), std::vector<std::string>{"model.sogmm"}) << "stage " << static_cast<int>(stage);
  }
  format::save(path, new_model);
  EXPECT_TRUE(test::bit_equal(format::load(path), new_model));
  struct stat st;
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);  // the replaced file keeps its permissions
}

TEST_F(Save, IoErrors) {
  const Model m = test::synthetic_model(2, 1);
  try {
    format::save(dir_ + "/no/such/dir/model.sogmm", m);
    ADD_FAILURE() << "save into a missing directory succeeded";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
  }
  try {
    format::load(dir_ + "/missing.sogmm");
    ADD_FAILURE() << "load of a missing file succeeded";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
  }
  try {
    format::read_info_file(dir_);  // a directory
    ADD_FAILURE() << "reading a directory succeeded";
  } catch (const Error& e) {
    EXPECT_TRUE(e.code() == ErrorCode::Io || e.code() == ErrorCode::Format) << e.what();
  }
  // An invalid model is refused before anything touches the disk.
  Model bad = m;
  bad.gmm.weights[0] = 2.0f;
  EXPECT_THROW(format::save(dir_ + "/bad.sogmm", bad), Error);
  EXPECT_TRUE(files().empty());
}

TEST_F(Save, TruncatedFileOnDiskIsRejectedByLoadAndReadInfo) {
  const std::string path = dir_ + "/model.sogmm";
  format::save(path, test::synthetic_model(12, 4));
  const std::vector<std::uint8_t> full = slurp(path);
  for (std::size_t n : {std::size_t{0}, std::size_t{5}, std::size_t{31}, std::size_t{100}, full.size() - 1}) {
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(full.data()), static_cast<std::streamsize>(n));
    for (int which = 0; which < 2; ++which) {
      try {
        if (which == 0) format::load(path);
        else format::read_info_file(path);
        ADD_FAILURE() << "accepted a file truncated to " << n;
      } catch (const format::FormatError& e) {
        EXPECT_EQ(e.reason(), "truncated") << n << ": " << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace sogmm
