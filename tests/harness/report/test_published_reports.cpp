// The committed reports/ are what `scripts/publish-reports.sh` produces at this commit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

namespace test_published_reports {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Fields that legitimately differ between two runs of the same build: clocks, dates, the
// machine, the commit (the report is regenerated after the commit that changes results), and
// whether the reference came from the cache.
const std::set<std::string> kIgnored = {"provenance", "wall_seconds", "cpu_seconds", "real_time_factor",
                                        "cost_ratio", "date", "git_commit", "hostname", "cached", "scene_file"};

void expect_same(const json& a, const json& b, const std::string& path, int& differences) {
  if (differences > 20) return;
  if (a.is_object() && b.is_object()) {
    for (const auto& [k, v] : a.items()) {
      if (kIgnored.count(k)) continue;
      if (!b.contains(k)) {
        ADD_FAILURE() << path << "." << k << " missing in the fresh run";
        ++differences;
        continue;
      }
      expect_same(v, b.at(k), path + "." + k, differences);
    }
    for (const auto& [k, v] : b.items())
      if (!kIgnored.count(k) && !a.contains(k)) {
        ADD_FAILURE() << path << "." << k << " missing in the published report";
        ++differences;
      }
    return;
  }
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) {
      ADD_FAILURE() << path << ": " << a.size() << " entries published, " << b.size() << " now";
      ++differences;
      return;
    }
    for (size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], path + "[" + std::to_string(i) + "]", differences);
    return;
  }
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    // Runs are deterministic on one machine and build; 1e-9 relative leaves room only for a
    // different libm, not for a change of results.
    if (!(std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)))) {
      ADD_FAILURE() << path << ": published " << x << ", now " << y;
      ++differences;
    }
    return;
  }
  if (a != b) {
    ADD_FAILURE() << path << ": published " << a.dump() << ", now " << b.dump();
    ++differences;
  }
}

class PublishedReport : public ::testing::TestWithParam<std::string> {};

TEST_P(PublishedReport, MatchesAFreshComparison) {
  const std::string name = GetParam();
  const std::string src = TIPPE_SOURCE_DIR;
  const fs::path out = fs::path(::testing::TempDir()) / ("published-" + name);
  fs::remove_all(out);
  // From the repository root with a relative scene path, as the publish script runs it.
  const std::string cmd = "cd " + src + " && " + std::string(TIPPE_BINARY_DIR) + "/tippe compare harness/scenes/" + name +
                          ".toml --out " + out.string() + " --jobs 1 --no-cache --no-plots > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream published(src + "/reports/" + name + "/comparison.json"), fresh(out / "comparison.json");
  ASSERT_TRUE(published.good() && fresh.good());
  int differences = 0;
  expect_same(json::parse(published), json::parse(fresh), name, differences);
  EXPECT_EQ(differences, 0) << "reports/ is out of date: run scripts/publish-reports.sh build";
  fs::remove_all(out);
}

std::vector<std::string> published() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(std::string(TIPPE_SOURCE_DIR) + "/reports"))
    if (e.is_directory() && fs::exists(e.path() / "comparison.json")) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

INSTANTIATE_TEST_SUITE_P(Reports, PublishedReport, ::testing::ValuesIn(published()),
                         [](const auto& info) { return info.param; });

}  // namespace

}  // namespace test_published_reports
