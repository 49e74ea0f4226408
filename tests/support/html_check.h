// A checker of the subset of HTML the comparison report writes, for the tests of its pages: balanced tags, quoted attributes, no raw '<' or stray '&'.
#pragma once

#include <algorithm>
#include <cctype>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace tippe::fixtures {

// Checks the subset of HTML the report uses: balanced tags (void elements excepted), quoted
// attributes, no raw '<' or stray '&' in text. Returns "" or the first problem; collects
// every <img src>.
inline std::string check_html(const std::string& h, std::vector<std::string>& images) {
  static const std::set<std::string> void_tags = {"meta", "img", "br", "hr", "link", "input"};
  std::vector<std::string> stack;
  size_t i = 0;
  auto line_of = [&](size_t pos) { return "line " + std::to_string(std::count(h.begin(), h.begin() + pos, '\n') + 1); };
  while (i < h.size()) {
    const char ch = h[i];
    if (ch == '&') {
      static const std::regex entity("&(#[0-9]+|[a-z]+);");
      std::smatch mt;
      const std::string rest = h.substr(i, 12);
      if (!std::regex_search(rest, mt, entity, std::regex_constants::match_continuous))
        return "stray '&' at " + line_of(i);
      i += mt.length(0);
      continue;
    }
    if (ch == '>') return "stray '>' at " + line_of(i);
    if (ch != '<') {
      ++i;
      continue;
    }
    if (h.compare(i, 4, "<!--") == 0) {
      const size_t e = h.find("-->", i);
      if (e == std::string::npos) return "unterminated comment";
      i = e + 3;
      continue;
    }
    if (h.compare(i, 2, "<!") == 0) {
      i = h.find('>', i) + 1;
      continue;
    }
    const bool closing = h.compare(i, 2, "</") == 0;
    size_t p = i + (closing ? 2 : 1);
    size_t q = p;
    while (q < h.size() && std::isalnum(static_cast<unsigned char>(h[q]))) ++q;
    const std::string name = h.substr(p, q - p);
    if (name.empty()) return "raw '<' at " + line_of(i);
    // Attributes: name="value" pairs, no '<' or '>' inside values.
    std::string attrs;
    size_t e = q;
    bool in_quote = false;
    for (; e < h.size(); ++e) {
      if (h[e] == '"') in_quote = !in_quote;
      if (in_quote && (h[e] == '<' || h[e] == '>')) return "'<' or '>' in an attribute at " + line_of(e);
      if (!in_quote && h[e] == '>') break;
    }
    if (e == h.size()) return "unterminated tag <" + name;
    attrs = h.substr(q, e - q);
    i = e + 1;
    if (closing) {
      if (stack.empty() || stack.back() != name)
        return "</" + name + "> closes <" + (stack.empty() ? std::string("nothing") : stack.back()) + "> at " +
               line_of(e);
      stack.pop_back();
      continue;
    }
    if (name == "img") {
      std::smatch mt;
      if (std::regex_search(attrs, mt, std::regex("src=\"([^\"]*)\""))) images.push_back(mt[1]);
    }
    if (void_tags.count(name) || (!attrs.empty() && attrs.back() == '/')) continue;
    stack.push_back(name);
    if (name == "style") {
      // CSS is raw text up to </style>.
      const size_t s = h.find("</style>", i);
      if (s == std::string::npos) return "unterminated <style>";
      i = s;
    }
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  return "";
}

}  // namespace tippe::fixtures
