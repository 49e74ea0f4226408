// Every published page (reports/**/*.html) displays: its local links and resources exist, and headless Chromium loads it with no failed load, script error or undecodable image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/support/page_check.h"
#include "tests/support/files.h"

namespace test_published_pages {

namespace {

namespace fs = std::filesystem;

// Without Chromium the browser tests fail: CI installs it (scripts/install-deps.sh), and a check
// that quietly stops checking is no check. A machine without it can say so explicitly.
bool chromium_may_be_missing() {
  const char* e = std::getenv("TIPPE_SKIP_BROWSER_TESTS");
  return e && std::string(e) == "1";
}

#define REQUIRE_CHROMIUM(exe)                                                                                  \
  const std::string exe = page_check::find_chromium();                                                        \
  if (exe.empty()) {                                                                                          \
    if (chromium_may_be_missing()) GTEST_SKIP() << "chromium not found; skipped as TIPPE_SKIP_BROWSER_TESTS=1 asks"; \
    FAIL() << "chromium not found on PATH (nor $TIPPE_CHROMIUM): install it with scripts/install-deps.sh, "   \
              "or set TIPPE_SKIP_BROWSER_TESTS=1 to skip the browser checks on this machine";                 \
  }

std::vector<fs::path> published_pages() {
  std::vector<fs::path> pages;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(TIPPE_SOURCE_DIR) / "reports"))
    if (e.is_regular_file() && e.path().extension() == ".html") pages.push_back(e.path());
  std::sort(pages.begin(), pages.end());
  return pages;
}

std::string joined(const std::vector<std::string>& problems) {
  std::string s;
  for (const std::string& p : problems) s += "\n  " + p;
  return s;
}

bool any_mentions(const std::vector<std::string>& problems, const std::string& what) {
  return std::any_of(problems.begin(), problems.end(), [&](const std::string& p) { return p.find(what) != std::string::npos; });
}

// reports/index.html and one page per scene and sweep: fewer pages means publishing lost some.
constexpr size_t kMinPublishedPages = 10;

TEST(PublishedPages, EveryLocalLinkAndResourceExists) {
  const auto pages = published_pages();
  ASSERT_GE(pages.size(), kMinPublishedPages);
  for (const fs::path& page : pages) {
    const auto problems = page_check::check_local_links(page);
    EXPECT_TRUE(problems.empty()) << page << ":" << joined(problems);
  }
}

TEST(PublishedPages, EveryPageLoadsInChromiumWithoutErrors) {
  REQUIRE_CHROMIUM(exe);
  const auto pages = published_pages();
  ASSERT_GE(pages.size(), kMinPublishedPages);
  TempDir work("tippe-pages");
  page_check::Chromium browser(exe, work.path());
  for (const fs::path& page : pages) {
    const auto problems = browser.load(page);
    EXPECT_TRUE(problems.empty()) << page << ":" << joined(problems);
  }
}

// The verdict an engine's record gives on a scene, as the matrix must colour it, worked out here
// from comparison.json: in the reference's regime when it inverts as the reference does (an
// engine that inverted and then ended early keeps its inversion); then, where both invert, the
// size of the inversion-time error (below 1 %, below 10 %, beyond); neither inverting is the
// regime alone; out of the regime, a run not ok ended early ("failed"), else the wrong regime.
std::string expected_verdict(const nlohmann::json& comparison, const nlohmann::json& engine) {
  const auto inverts = [](const nlohmann::json& s) { return s.contains("inversion_time") && s.at("inversion_time").is_number(); };
  const nlohmann::json& ref = comparison.at("reference").at("summary");
  const nlohmann::json& s = engine.at("summary");
  const bool ok = s.at("status") == "ok";
  if (inverts(s) == inverts(ref) && (ok || inverts(s))) {
    if (!inverts(ref)) return "regime";
    const nlohmann::json& rel = engine.at("metrics").at("inversion_time_rel_error");
    if (!rel.is_number()) return "regime";
    const double e = std::abs(rel.get<double>());
    return e < 0.01 ? "1pct" : e < 0.1 ? "10pct" : "beyond";
  }
  return ok ? "wrong" : "failed";
}

// The colour each verdict has on the page (reports/README.md's legend): six, all different.
const std::map<std::string, std::string> kVerdictColours = {
    {"1pct", "rgb(168, 219, 168)"}, {"regime", "rgb(212, 238, 212)"}, {"10pct", "rgb(253, 229, 166)"},
    {"beyond", "rgb(255, 184, 112)"}, {"wrong", "rgb(240, 140, 140)"}, {"failed", "rgb(189, 189, 189)"}};

// The index's first matrix as the browser shows it: the header's engines, and per row the scene
// and, per cell, its class, computed background colour, link (resolved by the browser) and text.
const char* const kReadMatrix = R"JS(
(() => {
  const t = document.querySelector('table.matrix');
  if (!t) return null;
  const engines = Array.from(t.querySelectorAll('thead th')).slice(1).map(th => th.textContent);
  const rows = Array.from(t.querySelectorAll('tbody tr')).map(tr => {
    const cells = Array.from(tr.children);
    return {scene: cells[0].textContent,
            cells: cells.slice(1).map(td => {
              const a = td.querySelector('a');
              return {cls: td.className, colour: getComputedStyle(td).backgroundColor, href: a ? a.href : '',
                      text: td.textContent};
            })};
  });
  return {engines: engines, rows: rows, matrices: document.querySelectorAll('table.matrix').length};
})()
)JS";

TEST(PublishedPages, VerdictMatrixShowsEveryRecordInItsColour) {
  REQUIRE_CHROMIUM(exe);
  // The records: every reports/SCENE/comparison.json, scenes in directory order, engines in the
  // order the records first name them.
  const fs::path reports = fs::path(TIPPE_SOURCE_DIR) / "reports";
  std::vector<std::pair<std::string, nlohmann::json>> records;
  for (const auto& e : fs::directory_iterator(reports))
    if (fs::exists(e.path() / "comparison.json")) records.push_back({e.path().filename().string(), nlohmann::json::parse(slurp(e.path() / "comparison.json"))});
  std::sort(records.begin(), records.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ASSERT_GE(records.size(), 10u);
  std::vector<std::string> engines;
  for (const auto& [dir, c] : records)
    for (const auto& e : c.at("engines"))
      if (std::find(engines.begin(), engines.end(), e.at("engine").get<std::string>()) == engines.end()) engines.push_back(e.at("engine"));
  size_t sweeps = 0;
  for (const auto& e : fs::directory_iterator(reports)) sweeps += fs::exists(e.path() / "records.jsonl") && fs::exists(e.path() / "sweep.json");

  TempDir work("tippe-pages");
  page_check::Chromium browser(exe, work.path());
  const auto problems = browser.load(reports / "index.html");
  ASSERT_TRUE(problems.empty()) << joined(problems);
  const nlohmann::json m = browser.evaluate(kReadMatrix);
  ASSERT_TRUE(m.is_object()) << "reports/index.html has no table.matrix";
  EXPECT_EQ(m.at("matrices").get<size_t>(), 1 + sweeps) << "one matrix for the comparisons and one per published sweep";
  ASSERT_EQ(m.at("engines").get<std::vector<std::string>>(), engines);
  ASSERT_EQ(m.at("rows").size(), records.size());
  std::set<std::string> colours;
  for (const auto& [kind, colour] : kVerdictColours) colours.insert(colour);
  EXPECT_EQ(colours.size(), kVerdictColours.size()) << "two verdicts share a colour";
  for (size_t i = 0; i < records.size(); ++i) {
    const auto& [dir, c] = records[i];
    const nlohmann::json& row = m.at("rows")[i];
    EXPECT_EQ(row.at("scene"), c.at("scene_name"));
    ASSERT_EQ(row.at("cells").size(), engines.size()) << dir;
    for (size_t k = 0; k < engines.size(); ++k) {
      const nlohmann::json& cell = row.at("cells")[k];
      const auto it = std::find_if(c.at("engines").begin(), c.at("engines").end(),
                                   [&](const nlohmann::json& e) { return e.at("engine") == engines[k]; });
      ASSERT_NE(it, c.at("engines").end()) << dir << " has no " << engines[k];
      const std::string want = expected_verdict(c, *it);
      const std::string where = dir + " / " + engines[k] + " (" + cell.at("text").get<std::string>() + ")";
      EXPECT_EQ(cell.at("cls"), "v-" + want) << where;
      EXPECT_EQ(cell.at("colour"), kVerdictColours.at(want)) << where;
      // The number in the cell: the signed inversion-time error where both invert.
      if (want == "1pct" || want == "10pct" || want == "beyond") {
        const double rel = it->at("metrics").at("inversion_time_rel_error").get<double>();
        EXPECT_EQ(cell.at("text").get<std::string>().substr(0, 1), rel >= 0 ? "+" : "-") << where;
        EXPECT_NE(cell.at("text").get<std::string>().find(" %"), std::string::npos) << where;
      }
      // The link leads to that scene's page, which exists.
      const std::string href = cell.at("href");
      const std::string suffix = "/reports/" + dir + "/index.html";
      ASSERT_GE(href.size(), suffix.size()) << where;
      EXPECT_EQ(href.substr(href.size() - suffix.size()), suffix) << where;
      EXPECT_TRUE(fs::exists(reports / dir / "index.html")) << where;
    }
  }
}

// The checks themselves, on pages broken on purpose: each must be caught, and a sound page with
// the same kinds of links must pass.
class BrokenPages : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string head = "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>t</title>";
    dir_.write("plot.svg",
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"><rect width=\"10\" height=\"10\"/></svg>");
    dir_.write("not-an-image.svg", "this is not SVG\n");
    dir_.write("data.csv", "t,theta\n0,0.1\n");
    dir_.write("sub/index.html", head + "</head><body><h2 id=\"results\">r</h2></body></html>");
    dir_.write("sound.html", head + "<style>p { color: #222 }</style></head><body>"
                                    "<nav><a href=\"#plots\">Plots</a> <a href=\"sub/\">sub</a> <a href=\"sub/index.html#results\">r</a>"
                                    " <a href=\"data.csv\">data</a> <a href=\"https://example.org/\">elsewhere</a></nav>"
                                    "<h2 id=\"plots\">Plots</h2><img src=\"plot.svg\" alt=\"a plot &amp; its caption\">"
                                    "<script>document.title = 'x < y';</script></body></html>");
    dir_.write("missing-svg.html", head + "</head><body><img src=\"gone.svg\" alt=\"\"></body></html>");
    dir_.write("missing-css.html", head + "<link rel=\"stylesheet\" href=\"gone.css\"></head><body></body></html>");
    dir_.write("throws.html", head + "</head><body><p>x</p><script>throw 1</script></body></html>");
    dir_.write("late-throw.html", head + "</head><body><script>setTimeout(() => { null.x = 1; }, 0)</script></body></html>");
    dir_.write("console-error.html", head + "</head><body><script>console.error('bad data')</script></body></html>");
    dir_.write("not-an-image.html", head + "</head><body><img src=\"not-an-image.svg\" alt=\"\"></body></html>");
    dir_.write("dead-links.html", head + "</head><body><a href=\"gone.csv\">d</a> <a href=\"#nowhere\">n</a>"
                                         " <a href=\"sub/index.html#elsewhere\">e</a> <a href=\"/srv/reports/x.html\">a</a></body></html>");
    dir_.write("network.html", head + "<script src=\"https://cdn.example.org/lib.js\"></script></head><body></body></html>");
  }
  fs::path page(const std::string& name) const { return dir_.path() / name; }
  TempDir dir_{"tippe-broken-pages"};
};

TEST_F(BrokenPages, LinkCheckCatchesEachBreakage) {
  EXPECT_TRUE(page_check::check_local_links(page("sound.html")).empty()) << joined(page_check::check_local_links(page("sound.html")));
  EXPECT_TRUE(any_mentions(page_check::check_local_links(page("missing-svg.html")), "gone.svg does not exist"));
  EXPECT_TRUE(any_mentions(page_check::check_local_links(page("missing-css.html")), "gone.css does not exist"));
  const auto dead = page_check::check_local_links(page("dead-links.html"));
  EXPECT_EQ(dead.size(), 4u) << joined(dead);
  EXPECT_TRUE(any_mentions(dead, "gone.csv does not exist"));
  EXPECT_TRUE(any_mentions(dead, "no element with id \"nowhere\" in the page"));
  EXPECT_TRUE(any_mentions(dead, "no element with id \"elsewhere\""));
  EXPECT_TRUE(any_mentions(dead, "an absolute path"));
  EXPECT_TRUE(any_mentions(page_check::check_local_links(page("network.html")), "a resource from the network"));
}

TEST_F(BrokenPages, ChromiumCatchesEachBreakage) {
  REQUIRE_CHROMIUM(exe);
  TempDir work("tippe-pages");
  page_check::Chromium browser(exe, work.path());
  const auto sound = browser.load(page("sound.html"));
  EXPECT_TRUE(sound.empty()) << joined(sound);
  const auto svg = browser.load(page("missing-svg.html"));
  EXPECT_TRUE(any_mentions(svg, "failed to load file://") && any_mentions(svg, "gone.svg: net::ERR_FILE_NOT_FOUND")) << joined(svg);
  EXPECT_TRUE(any_mentions(svg, "image not displayed (missing or not decodable): gone.svg")) << joined(svg);
  const auto css = browser.load(page("missing-css.html"));
  EXPECT_TRUE(any_mentions(css, "gone.css: net::ERR_FILE_NOT_FOUND")) << joined(css);
  const auto thrown = browser.load(page("throws.html"));
  EXPECT_TRUE(any_mentions(thrown, "script error: Uncaught")) << joined(thrown);
  const auto late = browser.load(page("late-throw.html"));
  EXPECT_TRUE(any_mentions(late, "script error: Uncaught TypeError")) << joined(late);
  const auto console = browser.load(page("console-error.html"));
  EXPECT_TRUE(any_mentions(console, "console.error: \"bad data\"")) << joined(console);
  const auto undecodable = browser.load(page("not-an-image.html"));
  EXPECT_TRUE(any_mentions(undecodable, "image not displayed (missing or not decodable): not-an-image.svg")) << joined(undecodable);
  // The request is made and refused on this machine (no resolver, a closed local proxy port).
  const auto network = browser.load(page("network.html"));
  EXPECT_TRUE(any_mentions(network, "request leaves the page's files: https://cdn.example.org/lib.js")) << joined(network);
  // A sound page after broken ones: nothing carried over from one load to the next.
  const auto again = browser.load(page("sound.html"));
  EXPECT_TRUE(again.empty()) << joined(again);
}

}  // namespace

}  // namespace test_published_pages
