// Smoke tests of `sogmm bench`: it runs, prints the table, writes the CSV, and
// its SOGMM rows agree with `sogmm eval` for the same seed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "octomap_adapter.hpp"
#include "synthetic_scene.hpp"

namespace fs = std::filesystem;

namespace {

struct CliRun {
  int code = -1;
  std::string out;
};

CliRun run(const std::string& args) {
  const std::string cmd = std::string(SOGMM_CLI_PATH) + " " + args + " 2>/dev/null";
  CliRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

using CsvRow = std::map<std::string, std::string>;
std::vector<CsvRow> read_csv(const fs::path& path) {
  std::ifstream f(path);
  std::vector<CsvRow> rows;
  std::string line;
  std::vector<std::string> header;
  auto split = [](const std::string& s) {
    std::vector<std::string> v;
    std::stringstream ss(s);
    for (std::string x; std::getline(ss, x, ',');) v.push_back(x);
    return v;
  };
  if (!std::getline(f, line)) return rows;
  header = split(line);
  while (std::getline(f, line)) {
    const auto v = split(line);
    CsvRow r;
    for (std::size_t i = 0; i < header.size() && i < v.size(); ++i) r[header[i]] = v[i];
    rows.push_back(r);
  }
  return rows;
}

class BenchCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("sogmm-bench-test-" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "seq" / "depth");
    fs::create_directories(dir_ / "seq" / "color");
    const sogmm::tools::LoadedFrame f = sogmm::tools::synthetic_frame();
    cv::Mat depth(f.height, f.width, CV_16UC1, const_cast<std::uint16_t*>(f.depth.data()));
    cv::Mat gray(f.height, f.width, CV_8UC1);
    for (int i = 0; i < f.width * f.height; ++i)
      gray.data[i] = static_cast<std::uint8_t>(std::lround(f.gray[i] * 255.0f));
    ASSERT_TRUE(cv::imwrite((dir_ / "depth.png").string(), depth));
    ASSERT_TRUE(cv::imwrite((dir_ / "color.png").string(), gray));
    for (const char* stem : {"a", "b"}) {
      fs::copy_file(dir_ / "depth.png", dir_ / "seq" / "depth" / (std::string(stem) + ".png"));
      fs::copy_file(dir_ / "color.png", dir_ / "seq" / "color" / (std::string(stem) + ".png"));
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static std::string frame_args() {
    return "--depth " + (dir_ / "depth.png").string() + " --color " + (dir_ / "color.png").string() +
           " --fx 525 --fy 525 --cx 319.5 --cy 239.5 --decimate 10";
  }
  static fs::path dir_;
};
fs::path BenchCli::dir_;

TEST_F(BenchCli, SingleFrameWritesTableAndCsv) {
  const fs::path out = dir_ / "out1";
  const CliRun r = run("bench " + frame_args() + " --name synth --methods octomap,ndt,sogmm --bandwidths 0.05 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("| frame | method |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| synth | NDT-0.02 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| synth | NDT-0.05 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| synth | SOGMM-0.05 |"), std::string::npos) << r.out;
  if (sogmm::bench::octomap_available())
    EXPECT_NE(r.out.find("| synth | OM-0.02 |"), std::string::npos) << r.out;
  else
    EXPECT_NE(r.out.find("OctoMap rows skipped"), std::string::npos) << r.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), sogmm::bench::octomap_available() ? 5u : 3u);
  for (const auto& row : rows) {
    EXPECT_GT(std::stod(row.at("n_points")), 1000);
    EXPECT_GE(std::stod(row.at("mre")), 0.0);  // NDT-0.02 can be 0: one point per voxel at d = 10
    EXPECT_LT(std::stod(row.at("mre")), 0.05) << row.at("method");
    EXPECT_GT(std::stod(row.at("psnr")), 10.0) << row.at("method");
    EXPECT_GT(std::stod(row.at("memory_bytes")), 0) << row.at("method");
  }
  // Plots: made, or the bench said why not.
  const bool plotted = fs::exists(out / "bench_psnr.png");
  EXPECT_TRUE(plotted || r.out.find("plots: skipped") != std::string::npos) << r.out;
}

TEST_F(BenchCli, SogmmAndFcRowsAgreeWithEval) {
  const fs::path out = dir_ / "out2";
  const CliRun b = run("bench " + frame_args() +
                    " --methods fc,sogmm --bandwidths 0.05 --fc-components 20 --seed 3 --no-plot --out " + out.string());
  ASSERT_EQ(b.code, 0) << b.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  const std::map<std::string, std::string> eval_flags = {{"FC-20", "--components 20"}, {"SOGMM-0.05", "--bandwidth 0.05"}};
  for (const auto& row : rows) {
    const CliRun e = run("eval " + frame_args() + " " + eval_flags.at(row.at("method")) + " --seed 3 --json");
    ASSERT_EQ(e.code, 0) << e.out;
    const auto j = nlohmann::json::parse(e.out);
    EXPECT_EQ(std::stoul(row.at("n_elements")), j["n_components"].get<std::size_t>());
    EXPECT_NEAR(std::stod(row.at("psnr")), j["psnr"].get<double>(), 1e-5) << row.at("method");
    EXPECT_NEAR(std::stod(row.at("psnr_paper")), j["psnr_paper"].get<double>(), 1e-5);
    EXPECT_NEAR(std::stod(row.at("mre")), j["mre"].get<double>(), 1e-7);
    EXPECT_NEAR(std::stod(row.at("fscore")), j["fscore"].get<double>(), 1e-5);
    EXPECT_EQ(std::stoul(row.at("memory_bytes")), j["model_bytes"].get<std::size_t>());
    EXPECT_GT(std::stoul(row.at("file_bytes")), 0u);
  }
}

TEST_F(BenchCli, FramesDirGivesARowPerFrameAndMethod) {
  const fs::path out = dir_ / "out3";
  const CliRun r = run("bench --frames-dir " + (dir_ / "seq").string() +
                    " --fx 525 --fy 525 --cx 319.5 --cy 239.5 --decimate 10 --methods ndt --no-plot --out " +
                    out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].at("frame"), "a");
  EXPECT_EQ(rows[2].at("frame"), "b");
  EXPECT_EQ(rows[0].at("psnr"), rows[2].at("psnr"));  // same image twice
}

TEST_F(BenchCli, UsageErrors) {
  EXPECT_EQ(run("bench " + frame_args() + " --methods gpoctomap --no-plot --out " + (dir_ / "x").string()).code, 2);
  EXPECT_EQ(run("bench --no-plot").code, 2);
  EXPECT_EQ(run("bench --frames-dir " + (dir_ / "missing").string() + " --fx 1 --fy 1 --cx 0 --cy 0").code, 4);
}

TEST(BenchRealFrame, LivingroomNdtAndOctoMap) {
  const fs::path root = fs::path(SOGMM_SHARED_DATA) / "rgbd" / "livingroom";
  if (!fs::exists(root / "depth" / "00000.png")) GTEST_SKIP() << "no shared data at " << root;
  const fs::path out = fs::temp_directory_path() / ("sogmm-bench-real-" + std::to_string(::getpid()));
  const CliRun r = run("bench --depth " + (root / "depth" / "00000.png").string() + " --color " +
                    (root / "color" / "00000.jpg").string() + " --intrinsics " + (root / "intrinsics.json").string() +
                    " --methods octomap,ndt --no-plot --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto rows = read_csv(out / "results.csv");
  ASSERT_EQ(rows.size(), sogmm::bench::octomap_available() ? 4u : 2u);
  for (const auto& row : rows) {
    EXPECT_GT(std::stoul(row.at("n_points")), 5000u);
    EXPECT_LT(std::stod(row.at("mre")), 0.05);
  }
  std::error_code ec;
  fs::remove_all(out, ec);
}

}  // namespace
