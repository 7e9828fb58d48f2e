// The option registry (sogmm/options.hpp): every row reaches its own field,
// accepts its default, refuses what its rule refuses, and the core's own
// validate() functions apply the same rules as the C API's setters.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "sogmm/error.hpp"
#include "sogmm/options.hpp"

namespace sogmm {
namespace {

// Every row's value in `s`, as doubles (I64 rows converted exactly enough
// for the values used here).
std::vector<double> all_values(const Settings& s) {
  std::vector<double> v;
  for (const OptionSpec& o : option_specs())
    v.push_back(o.type == OptionType::F64 ? o.get_f64(s) : static_cast<double>(o.get_i64(s)));
  return v;
}

// An accepted value other than the default: the bound on the far side.
template <typename T>
T other_value(T def, T lower, T upper) {
  return def != upper ? upper : lower;
}

TEST(OptionRegistry, KeysAndNamesAreUniqueSortedAndNamedAfterTheCMacro) {
  std::set<int> keys;
  std::set<std::string> names;
  int previous = 0;
  for (const OptionSpec& o : option_specs()) {
    const int key = static_cast<int>(o.key);
    EXPECT_GT(key, previous) << o.name;
    previous = key;
    EXPECT_TRUE(keys.insert(key).second) << o.name;
    EXPECT_TRUE(names.insert(o.name).second) << o.name;
    EXPECT_EQ(std::string(o.name).rfind("SOGMM_OPT_", 0), 0u) << o.name;
    EXPECT_LT(key, 10000) << "option keys are below the info keys";
    EXPECT_EQ(find_option(key), &o);
    EXPECT_NE(std::string(o.range), "");
    EXPECT_NE(std::string(o.doc), "");
  }
  EXPECT_EQ(find_option(99), nullptr);
}

TEST(OptionRegistry, EveryDefaultIsAcceptedByItsOwnRule) {
  for (const OptionSpec& o : option_specs()) {
    Settings s;
    if (o.type == OptionType::F64) {
      EXPECT_NO_THROW(set_option(s, o, default_f64(o))) << o.name;
    } else {
      EXPECT_NO_THROW(set_option(s, o, default_i64(o))) << o.name;
    }
  }
}

// Each row reaches a field of its own: setting it to another accepted value
// changes what that row reads and no other row (so no two rows share a
// field, and no accessor converts a value away).
TEST(OptionRegistry, EachRowReachesItsOwnField) {
  const std::vector<double> before = all_values(Settings{});
  const auto& specs = option_specs();
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const OptionSpec& o = specs[i];
    Settings s;
    double want;
    if (o.type == OptionType::F64) {
      // An accepted finite value different from the default.
      double v = other_value(default_f64(o), o.lower, o.upper);
      if (!std::isfinite(v) || (o.accepts_f64 && !o.accepts_f64(v))) v = default_f64(o) * 2 + 1;
      if (o.accepts_f64 && !o.accepts_f64(v)) v = default_f64(o) + 0.5;
      ASSERT_TRUE(!o.accepts_f64 || o.accepts_f64(v)) << o.name;
      set_option(s, o, v);
      want = v;
    } else {
      std::int64_t v = other_value(default_i64(o), o.lower_i64, std::min<std::int64_t>(o.upper_i64, 1 << 20));
      if (o.key == OptionKey::MAX_DECODED_BYTES) v = 12345;  // 0 would restore the default
      set_option(s, o, v);
      want = static_cast<double>(v);
    }
    const std::vector<double> after = all_values(s);
    for (std::size_t j = 0; j < specs.size(); ++j) {
      if (j == i) {
        EXPECT_EQ(after[j], want) << o.name;
        EXPECT_NE(after[j], before[j]) << o.name << " did not change";
      } else {
        EXPECT_EQ(after[j], before[j]) << "setting " << o.name << " changed " << specs[j].name;
      }
    }
  }
}

TEST(OptionRegistry, RefusesOutOfRangeValuesWithTheKeyAndRuleInTheMessage) {
  Settings s;
  try {
    set_option(s, *find_option(static_cast<int>(OptionKey::TOL)), -1e-9);
    FAIL() << "tol -1e-9 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("102 (SOGMM_OPT_TOL)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(">= 0, finite"), std::string::npos) << e.what();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const OptionSpec& o : option_specs()) {
    if (o.type == OptionType::F64) {
      EXPECT_THROW(set_option(s, o, nan), Error) << o.name;
    } else if (o.lower_i64 > std::numeric_limits<std::int64_t>::min()) {
      EXPECT_THROW(set_option(s, o, std::int64_t{o.lower_i64 - 1}), Error) << o.name;
    }
  }
  // A refused value leaves the settings as they were.
  EXPECT_EQ(all_values(s), all_values(Settings{}));
}

TEST(OptionRegistry, SentinelsAndSharedFields) {
  Settings s;
  const OptionSpec& reg = *find_option(static_cast<int>(OptionKey::REG_COVAR));
  set_option(s, reg, 1e-4);
  EXPECT_EQ(s.fit.em.reg_covar, 1e-4);
  set_option(s, reg, -1.0);  // SOGMM_REG_COVAR_AUTO
  EXPECT_FALSE(s.fit.em.reg_covar.has_value());
  EXPECT_THROW(set_option(s, reg, -0.5), Error);

  const OptionSpec& cap = *find_option(static_cast<int>(OptionKey::MAX_DECODED_BYTES));
  set_option(s, cap, std::int64_t{4096});
  EXPECT_EQ(s.read.max_decoded_bytes, 4096u);
  EXPECT_EQ(s.write.max_decoded_bytes, 4096u);
  set_option(s, cap, std::int64_t{0});
  EXPECT_EQ(s.read.max_decoded_bytes, format::kDefaultMaxDecodedBytes);

  set_option(s, *find_option(static_cast<int>(OptionKey::THREADS)), std::int64_t{3});
  EXPECT_EQ(s.fit.em.threads, 3);
  EXPECT_EQ(s.query.threads, 3);
}

// The core's validate() functions refuse what the registry refuses (the C
// API and the core used to disagree on tol = 0).
TEST(OptionRegistry, CoreValidationAppliesTheRegistryRules) {
  Settings s;
  EXPECT_NO_THROW(set_option(s, *find_option(static_cast<int>(OptionKey::TOL)), 0.0));
  MapOptions m;
  m.novelty_bandwidth_scale = 1.5;
  EXPECT_THROW(validate(m), Error);
  m = MapOptions{};
  m.revisit_refit_ratio = 0.5;
  EXPECT_THROW(validate(m), Error);
  DepthOptions d;
  d.decimate = 2048;  // [1, 1024], as the C API's SOGMM_OPT_DECIMATION
  EXPECT_THROW(validate(d), Error);
  d = DepthOptions{};
  EXPECT_NO_THROW(validate(d));
  EXPECT_NO_THROW(validate(map_options(Settings{})));
  Settings bad;
  bad.depth.depth_min = 5.0;  // above depth_max: a rule across two keys
  EXPECT_THROW(map_options(bad), Error);
}

}  // namespace
}  // namespace sogmm
