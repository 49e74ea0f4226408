// The ledger chart: bars on one linear scale, each run's terms ending at its E_final - E0, names escaped, drawn from the record alone and shown in the ledger section.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/report/ledger_chart.h"
#include "harness/report/report.h"
#include "tests/support/files.h"

namespace test_ledger_chart {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

// One drawn term: its value (/ |E0|, signed) and where it sits.
struct Drawn {
  std::string term;
  double value, x, width, y;
};
std::vector<Drawn> drawn_terms(const std::string& svg) {
  std::vector<Drawn> out;
  const std::regex rect(R"re(<rect class="term" data-term="([a-z_]+)" data-value="([^"]+)" x="([^"]+)" y="([^"]+)" width="([^"]+)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), rect); it != std::sregex_iterator(); ++it)
    out.push_back({(*it)[1], std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[5]), std::stod((*it)[4])});
  return out;
}
// The black ticks at E_final - E0: value and x.
std::vector<std::pair<double, double>> totals(const std::string& svg) {
  std::vector<std::pair<double, double>> out;
  const std::regex line(R"re(<line class="total" data-value="([^"]+)" x1="([^"]+)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), line); it != std::sregex_iterator(); ++it)
    out.push_back({std::stod((*it)[1]), std::stod((*it)[2])});
  return out;
}

json summary(double e0, double e1, json terms) {
  json s = {{"energy_initial", e0}, {"energy_final", e1}};
  for (auto& [k, v] : terms.items()) s[k] = v;
  return s;
}

// E1 - E0 = normal + friction + drilling - impacts + numerical in every run (the ledger's
// definition), with a run whose terms are partly n/a (null) and one without a ledger.
json synthetic() {
  json c;
  c["reference"]["summary"] = summary(2.0, 1.0, {{"normal_work", 0.1}, {"friction_work", -1.2}, {"drilling_work", 0.0},
                                                 {"impact_energy", 0.1}, {"numerical_energy_final", 0.2}});
  c["engines"] = json::array();
  c["engines"].push_back({{"engine", "soft"},
                          {"summary", summary(-4.0, -4.8, {{"normal_work", -0.4}, {"friction_work", -0.2},
                                                           {"drilling_work", nullptr}, {"impact_energy", nullptr},
                                                           {"numerical_energy_final", -0.2}})}});
  c["engines"].push_back({{"engine", "<b onload=\"x\">&'"},
                          {"summary", summary(1.0, 1.1, {{"normal_work", 0.05}, {"friction_work", -0.05},
                                                         {"numerical_energy_final", 0.1}})}});
  c["engines"].push_back({{"engine", "old"}, {"summary", {{"energy_initial", 1.0}, {"energy_final", 0.5}}}});
  return c;
}

}  // namespace

TEST(LedgerChart, OneLinearScaleAndEveryStackEndsAtItsTotal) {
  const std::string svg = ledger_chart_svg(synthetic());
  ASSERT_FALSE(svg.empty());
  const auto d = drawn_terms(svg);
  // reference: normal, friction, impacts (drilling 0 is not drawn), numerical; soft: normal,
  // friction, numerical (n/a left out); the escaped one: three; "old" has no ledger.
  ASSERT_EQ(d.size(), 4u + 3u + 3u);
  // One scale: width / |value| is the same for every bar (to the 2 decimals of the coordinates).
  const double scale = d[0].width / std::abs(d[0].value);
  for (const Drawn& x : d) EXPECT_NEAR(x.width, scale * std::abs(x.value), 0.02) << x.term;
  // The impacts are drawn as removed energy (negative): 0.1 / |E0| = 0.05 to the left.
  bool impacts = false;
  for (const Drawn& x : d)
    if (x.term == "impact_energy") {
      impacts = true;
      EXPECT_DOUBLE_EQ(x.value, -0.05);
    }
  EXPECT_TRUE(impacts);
  // Each run's tick sits at its E1 - E0 / |E0| on the same scale as the bars, and the bars add up
  // to it (the ledger closes in these records, so the drawing must too).
  const auto t = totals(svg);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_DOUBLE_EQ(t[0].first, -0.5);
  EXPECT_DOUBLE_EQ(t[1].first, -0.2);
  EXPECT_NEAR(t[2].first, 0.1, 1e-12);
  size_t k = 0;
  for (size_t run = 0; run < t.size(); ++run) {
    const double y = d[k].y;
    double sum = 0.0, neg = 0.0, neg_left = 1e300, pos_left = 1e300;
    for (; k < d.size() && d[k].y == y; ++k) {
      sum += d[k].value;
      if (d[k].value < 0) {
        neg += d[k].value;
        neg_left = std::min(neg_left, d[k].x);
      } else {
        pos_left = std::min(pos_left, d[k].x);
      }
    }
    EXPECT_NEAR(sum, t[run].first, 1e-9) << "run " << run;
    // Zero is where the negative stack ends and the positive one begins; the tick sits at
    // zero + scale * total.
    const double zero = neg_left < 1e300 ? neg_left + scale * std::abs(neg) : pos_left;
    if (neg_left < 1e300 && pos_left < 1e300) {
      EXPECT_NEAR(pos_left, zero, 0.02) << "run " << run;
    }
    EXPECT_NEAR(t[run].second, zero + scale * t[run].first, 0.05) << "run " << run;
  }
}

TEST(LedgerChart, NamesFromTheRecordAreEscaped) {
  const std::string svg = ledger_chart_svg(synthetic());
  EXPECT_EQ(svg.find("<b onload"), std::string::npos);
  EXPECT_NE(svg.find("&lt;b onload=&quot;x&quot;&gt;&amp;&#39;"), std::string::npos);
  EXPECT_EQ(svg.find("<script"), std::string::npos);
}

// The SVG declares no encoding, so XML reads it as UTF-8: a name with a byte that is not UTF-8,
// or a control character XML 1.0 does not allow, must not make the file unreadable.
TEST(LedgerChart, NamesFromTheRecordBecomeValidXmlText) {
  json c = synthetic();
  c["engines"][0]["engine"] = std::string("so\xff\x01" "ft");
  const std::string svg = ledger_chart_svg(c);
  EXPECT_EQ(svg.find('\xff'), std::string::npos);
  EXPECT_EQ(svg.find('\x01'), std::string::npos);
  EXPECT_NE(svg.find(">so"), std::string::npos);
}

TEST(LedgerChart, NothingWithoutALedger) {
  json c = synthetic();
  c["reference"]["summary"].erase("numerical_energy_final");
  for (auto& e : c["engines"]) e["summary"].erase("numerical_energy_final");
  EXPECT_TRUE(ledger_chart_svg(c).empty());
}

// A published comparison: the chart is drawn from comparison.json alone (no trajectory, no
// gnuplot), its stacks close to each run's energy change, and the page shows it once, in the
// Energy ledger section; without plots an earlier chart is kept, and a record without a ledger
// removes a stale one.
TEST(LedgerChart, ThePageShowsItInTheLedgerSection) {
  const json c = json::parse(slurp(fs::path(TIPPE_SOURCE_DIR) / "reports/toy_viscous/comparison.json"));
  TempDir dir("tippe-ledger-chart");
  write_report(dir.path().string(), c, true);
  const fs::path chart = dir.path() / kLedgerChartFile;
  ASSERT_TRUE(fs::exists(chart));
  const std::string svg = slurp(chart);
  const auto d = drawn_terms(svg);
  const auto t = totals(svg);
  ASSERT_EQ(t.size(), 1u + c.at("engines").size());
  // Closure of the published records, as drawn: 1e-9 E0 (the reference closes to 1e-10 E0, the
  // engines by the remainder's definition; the chart prints 6 significant digits: 1e-6 relative).
  for (size_t run = 0, k = 0; run < t.size(); ++run) {
    double sum = 0.0;
    const double y = d[k].y;
    for (; k < d.size() && d[k].y == y; ++k) sum += d[k].value;
    EXPECT_NEAR(sum, t[run].first, 5e-6 * std::max(1.0, std::abs(t[run].first))) << "run " << run;
  }
  const std::string md = slurp(dir.path() / "report.md");
  const size_t at = md.find(kLedgerChartFile), ledger = md.find("## Energy ledger"), findings = md.find("## Findings");
  ASSERT_NE(at, std::string::npos);
  EXPECT_GT(at, ledger);
  EXPECT_LT(at, findings);
  EXPECT_EQ(md.find(kLedgerChartFile, at + 1), std::string::npos) << "shown once";
  EXPECT_NE(slurp(dir.path() / "index.html").find(std::string("src=\"") + kLedgerChartFile), std::string::npos);

  write_report(dir.path().string(), c, false);
  EXPECT_TRUE(fs::exists(chart)) << "kept without plots";
  EXPECT_NE(slurp(dir.path() / "report.md").find(kLedgerChartFile), std::string::npos);

  json old = c;
  old["reference"]["summary"].erase("numerical_energy_final");
  for (auto& e : old["engines"]) e["summary"].erase("numerical_energy_final");
  write_report(dir.path().string(), old, true);
  EXPECT_FALSE(fs::exists(chart)) << "a stale chart must not stand beside records without a ledger";
  EXPECT_EQ(slurp(dir.path() / "report.md").find(kLedgerChartFile), std::string::npos);
}

}  // namespace test_ledger_chart
