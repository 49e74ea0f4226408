// Every published page (reports/index.html and each report's index.html) has every resource and link it names, and renders in headless Chromium without a script error.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "support/files.h"

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> published_pages() {
  std::vector<fs::path> pages;
  const fs::path reports = fs::path(TIPPE_SOURCE_DIR) / "reports";
  if (fs::exists(reports / "index.html")) pages.push_back(reports / "index.html");
  for (const auto& entry : fs::directory_iterator(reports))
    if (fs::exists(entry.path() / "index.html")) pages.push_back(entry.path() / "index.html");
  std::sort(pages.begin(), pages.end());
  return pages;
}

// Every src= and href= of a page: a local file relative to the page that must exist, or an
// anchor (#id) that the page must define. Nothing from the network: the pages are read offline.
std::vector<std::string> broken_references(const fs::path& page) {
  const std::string html = slurp(page);
  std::vector<std::string> broken;
  std::set<std::string> ids;
  static const std::regex id_re(R"re(\sid="([^"]*)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), id_re); it != std::sregex_iterator(); ++it)
    ids.insert((*it)[1]);
  static const std::regex ref_re(R"re(\s(src|href)="([^"]*)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), ref_re); it != std::sregex_iterator(); ++it) {
    const std::string kind = (*it)[1], target = (*it)[2];
    if (target.find("://") != std::string::npos || target.rfind("//", 0) == 0) {
      broken.push_back(kind + "=" + target + " (a network resource)");
    } else if (!target.empty() && target[0] == '#') {
      if (!ids.count(target.substr(1))) broken.push_back(kind + "=" + target + " (no such id)");
    } else if (!fs::exists(page.parent_path() / target)) {
      broken.push_back(kind + "=" + target + " (no such file)");
    }
  }
  return broken;
}

bool have_chromium() { return std::system("command -v chromium >/dev/null 2>&1") == 0; }

}  // namespace

TEST(PublishedPages, EveryResourceAndLinkIsThere) {
  const auto pages = published_pages();
  ASSERT_FALSE(pages.empty());
  for (const fs::path& page : pages) {
    for (const std::string& b : broken_references(page)) ADD_FAILURE() << page << ": " << b;
    EXPECT_EQ(slurp(page).find("<script"), std::string::npos) << page << ": the pages have no scripts";
  }
}

TEST(PublishedPages, TheCheckerCatchesAMissingImageAndAnchor) {
  TempDir dir{"tippe-render"};
  const std::string page = dir.write("index.html",
                                     "<html><body><h2 id=\"sec-1\">a</h2><a href=\"#sec-1\">ok</a>"
                                     "<a href=\"#sec-9\">no</a><img src=\"there.svg\"><img src=\"gone.svg\">"
                                     "<img src=\"https://example.org/x.png\"></body></html>");
  dir.write("there.svg", "<svg/>");
  const auto broken = broken_references(page);
  ASSERT_EQ(broken.size(), 3u);
  EXPECT_NE(broken[0].find("#sec-9"), std::string::npos);
  EXPECT_NE(broken[1].find("gone.svg"), std::string::npos);
  EXPECT_NE(broken[2].find("network"), std::string::npos);
}

// Chromium logs a page's console messages (a script error among them) with --enable-logging;
// a page that renders cleanly logs none. One process per page: ~1.5 s each.
TEST(PublishedPages, RenderInHeadlessChromiumWithoutAConsoleMessage) {
  if (!have_chromium()) GTEST_SKIP() << "chromium not installed (scripts/install-deps.sh installs it)";
  TempDir dir{"tippe-render"};
  // The checker fails on a page with a script error.
  const std::vector<std::pair<std::string, bool>> cases = {
      {dir.write("bad.html", "<!DOCTYPE html><html><body><script>undefinedFunction();</script></body></html>"), false}};
  std::vector<std::pair<std::string, bool>> all = cases;
  for (const fs::path& p : published_pages()) all.push_back({p.string(), true});
  for (const auto& [page, clean] : all) {
    const fs::path log = dir.path() / "chromium.log", dom = dir.path() / "dom.html";
    const std::string cmd = "chromium --headless --no-sandbox --disable-gpu --user-data-dir=" +
                            (dir.path() / "profile").string() + " --enable-logging=stderr --v=0 --dump-dom 'file://" +
                            fs::absolute(page).string() + "' >" + dom.string() + " 2>" + log.string();
    const int rc = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 0) << cmd << "\n" << slurp(log);
    const std::string text = slurp(log);
    const bool console = text.find(":CONSOLE") != std::string::npos;
    EXPECT_EQ(console, !clean) << page << "\n" << text.substr(0, 2000);
    EXPECT_NE(slurp(dom).find("</body>"), std::string::npos) << page << ": no document rendered";
  }
}
