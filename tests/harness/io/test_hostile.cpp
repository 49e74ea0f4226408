// The table of hostile inputs (tests/hostile/cases.toml): each case runs `tippe` commands in a fresh directory and checks exit codes, messages and what is left on disk.
//
// The format of a case (see the file's header for an example):
//   name      a unique name (letters, digits, '_'); the test's name
//   issue     free text: which item of which issue it guards (optional)
//   [[case.file]]  files made before the first step (and [[case.step.file]] before one step):
//     path     relative to the case's directory
//     content  the bytes (TOML's escapes, plus the placeholders below), or
//     from     a file relative to the source root, copied, with
//     set      "KEY=VALUE" edits applied to its TOML like --set (tables made as needed), or
//     replace  [REGEX, REPLACEMENT] applied to the file already there (a record a step wrote)
//   [[case.step]]  the commands, in order:
//     args     tippe's arguments (without the program)
//     exit     the expected exit code (required)
//     stderr   a substring stderr must hold (optional); stdout likewise
//     internal true when the step may print "error: internal" (default false: that is a bug)
//     timeout  seconds before the step counts as hung (default 120)
//   contains  [[PATH, TEXT], ...]: files that must hold TEXT after the last step (or that step)
//   exists / absent   paths relative to the case's directory, '*' matching any characters
//                     (also '/'), that must / must not exist after the last step (in a
//                     [[case.step]]: after that step)
//   temporaries       false when *.tmp.* files may be left (default true: none may be)
//   sanitized         false for a case too long under ASan/UBSan (default true); skipped there
// Placeholders in path, content, set, args, exists and absent: {dir} the case's directory,
// {source} the source root, {0xHH} the byte HH (a path that is not UTF-8), {range:N:TEXT} TEXT N
// times joined by ", " with '#' counting 1..N (a large input). Every step runs with
// its working directory in the case's directory, and no file of the source tree may change.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/files.h"
#include "tests/support/process.h"

namespace test_hostile {

namespace fs = std::filesystem;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";
const std::string kCases = kSource + "/tests/hostile/cases.toml";

struct FileSpec {
  std::string path, content, from;
  std::vector<std::string> set;
  std::vector<std::string> replace;  // empty, or {regex, replacement}
  bool has_content = false;
};

// What must hold on disk after a step (or after the last one).
struct Checks {
  std::vector<std::string> exists, absent;
  std::vector<std::pair<std::string, std::string>> contains;  // (path, substring)
};

struct Step {
  std::vector<std::string> args;
  int exit = 0;
  std::string stderr_text, stdout_text;
  bool internal = false;
  double timeout = 120;
  std::vector<FileSpec> files;
  Checks checks;
};

struct Case {
  std::string name, issue;
  std::vector<FileSpec> files;
  std::vector<Step> steps;
  Checks checks;
  bool temporaries = true;
  bool sanitized = true;
};

// A malformed cases file is a failure of every test that reads it, with its reason.
[[noreturn]] void bad(const std::string& where, const std::string& why) {
  throw std::runtime_error(kCases + ": " + where + ": " + why);
}

std::vector<std::string> strings(const toml::table& t, const char* key, const std::string& where) {
  std::vector<std::string> out;
  const toml::node* n = t.get(key);
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a) bad(where + "." + key, "expected an array of strings");
  for (const toml::node& e : *a) {
    if (!e.is_string()) bad(where + "." + key, "expected an array of strings");
    out.push_back(e.as_string()->get());
  }
  return out;
}

// A key the runner does not know is a typo that would silently check nothing.
void keys(const toml::table& t, const std::string& where, std::initializer_list<const char*> allowed) {
  for (auto&& [k, v] : t) {
    (void)v;
    // A copy: C++17 lambdas cannot capture a structured binding (clang refuses it).
    const std::string key(k.str());
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }))
      bad(where + "." + key, "unknown key");
  }
}

Checks checks_of(const toml::table& t, const std::string& w) {
  Checks c;
  c.exists = strings(t, "exists", w);
  c.absent = strings(t, "absent", w);
  if (const toml::node* n = t.get("contains")) {
    const toml::array* a = n->as_array();
    if (!a) bad(w + ".contains", "expected [[PATH, TEXT], ...]");
    for (const toml::node& e : *a) {
      const toml::array* pair = e.as_array();
      if (!pair || pair->size() != 2 || !pair->get(0)->is_string() || !pair->get(1)->is_string())
        bad(w + ".contains", "expected [[PATH, TEXT], ...]");
      c.contains.emplace_back(pair->get(0)->as_string()->get(), pair->get(1)->as_string()->get());
    }
  }
  return c;
}

std::vector<FileSpec> files_of(const toml::table& t, const std::string& where) {
  std::vector<FileSpec> out;
  const toml::node* n = t.get("file");
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a) bad(where + ".file", "expected [[...file]] tables");
  for (size_t i = 0; i < a->size(); ++i) {
    const std::string w = where + ".file[" + std::to_string(i) + "]";
    const toml::table* f = a->get(i)->as_table();
    if (!f) bad(w, "expected a table");
    keys(*f, w, {"path", "content", "from", "set", "replace"});
    FileSpec s;
    s.path = f->get("path") && f->get("path")->is_string() ? f->get("path")->as_string()->get() : "";
    if (s.path.empty()) bad(w + ".path", "missing");
    if (const toml::node* c = f->get("content")) {
      if (!c->is_string()) bad(w + ".content", "expected a string");
      s.content = c->as_string()->get();
      s.has_content = true;
    }
    if (const toml::node* c = f->get("from")) {
      if (!c->is_string()) bad(w + ".from", "expected a string");
      s.from = c->as_string()->get();
    }
    s.set = strings(*f, "set", w);
    s.replace = strings(*f, "replace", w);
    const int kinds = s.has_content + !s.from.empty() + !s.replace.empty();
    if (kinds != 1) bad(w, "needs exactly one of content, from (with set) or replace");
    if (!s.replace.empty() && s.replace.size() != 2) bad(w + ".replace", "expected [REGEX, REPLACEMENT]");
    out.push_back(s);
  }
  return out;
}

std::vector<Case> load_cases() {
  toml::table root;
  try {
    root = toml::parse_file(kCases);
  } catch (const toml::parse_error& e) {
    bad("line " + std::to_string(e.source().begin.line), std::string(e.description()));
  }
  std::vector<Case> out;
  const toml::array* cases = root.get("case") ? root.get("case")->as_array() : nullptr;
  if (!cases || cases->empty()) bad("case", "no [[case]] tables");
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < cases->size(); ++i) {
    const std::string w = "case[" + std::to_string(i) + "]";
    const toml::table* t = cases->get(i)->as_table();
    if (!t) bad(w, "expected a table");
    Case c;
    c.name = t->get("name") && t->get("name")->is_string() ? t->get("name")->as_string()->get() : "";
    if (c.name.empty() || c.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") !=
                              std::string::npos)
      bad(w + ".name", "missing or not letters, digits and '_'");
    if (!names.emplace(c.name, i).second) bad(w + ".name", c.name + " is also case[" + std::to_string(names[c.name]) + "]");
    if (const toml::node* n = t->get("issue"); n && n->is_string()) c.issue = n->as_string()->get();
    c.files = files_of(*t, w);
    keys(*t, w, {"name", "issue", "file", "step", "exists", "absent", "contains", "temporaries", "sanitized"});
    c.checks = checks_of(*t, w);
    if (const toml::node* n = t->get("temporaries")) c.temporaries = n->value_or(true);
    if (const toml::node* n = t->get("sanitized")) c.sanitized = n->value_or(true);
    const toml::array* steps = t->get("step") ? t->get("step")->as_array() : nullptr;
    if (!steps || steps->empty()) bad(w + ".step", "no [[case.step]] tables");
    for (size_t k = 0; k < steps->size(); ++k) {
      const std::string ws = w + ".step[" + std::to_string(k) + "]";
      const toml::table* st = steps->get(k)->as_table();
      if (!st) bad(ws, "expected a table");
      Step s;
      s.args = strings(*st, "args", ws);
      if (s.args.empty()) bad(ws + ".args", "missing");
      const auto exit = st->get("exit") ? st->get("exit")->value<int64_t>() : std::nullopt;
      if (!exit) bad(ws + ".exit", "missing (the expected exit code)");
      s.exit = static_cast<int>(*exit);
      s.stderr_text = st->get("stderr") ? st->get("stderr")->value_or(std::string()) : "";
      s.stdout_text = st->get("stdout") ? st->get("stdout")->value_or(std::string()) : "";
      s.internal = st->get("internal") ? st->get("internal")->value_or(false) : false;
      s.timeout = st->get("timeout") ? st->get("timeout")->value_or(120.0) : 120.0;
      keys(*st, ws, {"args", "exit", "stderr", "stdout", "internal", "timeout", "file", "exists", "absent", "contains"});
      s.files = files_of(*st, ws);
      s.checks = checks_of(*st, ws);
      c.steps.push_back(s);
    }
    out.push_back(c);
  }
  return out;
}

// {dir}, {source} and {0xHH}.
std::string expand(const std::string& text, const fs::path& dir) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (text.compare(i, 5, "{dir}") == 0) {
      out += dir.string();
      i += 5;
    } else if (text.compare(i, 8, "{source}") == 0) {
      out += kSource;
      i += 8;
    } else if (text.compare(i, 7, "{range:") == 0 && text.find('}', i) != std::string::npos) {
      // {range:N:TEXT}: TEXT N times, '#' in it counting 1..N, joined by ", " (large inputs).
      const size_t close = text.find('}', i), colon = text.find(':', i + 7);
      if (colon == std::string::npos || colon > close) bad("range", "expected {range:N:TEXT}");
      const int n = std::stoi(text.substr(i + 7, colon - i - 7));
      const std::string item = text.substr(colon + 1, close - colon - 1);
      for (int k = 1; k <= n; ++k) {
        std::string one = item;
        for (size_t h; (h = one.find('#')) != std::string::npos;) one.replace(h, 1, std::to_string(k));
        out += (k > 1 ? ", " : "") + one;
      }
      i = close + 1;
    } else if (text.compare(i, 3, "{0x") == 0 && i + 5 < text.size() && text[i + 5] == '}' &&
               std::isxdigit(static_cast<unsigned char>(text[i + 3])) &&
               std::isxdigit(static_cast<unsigned char>(text[i + 4]))) {
      out += static_cast<char>(std::stoi(text.substr(i + 3, 2), nullptr, 16));
      i += 6;
    } else {
      out += text[i++];
    }
  }
  return out;
}

// KEY=VALUE into a TOML document, VALUE a TOML value or else a string (as tippe's --set).
void apply_set(toml::table& root, const std::string& edit) {
  const size_t eq = edit.find('=');
  if (eq == std::string::npos) bad("set", "\"" + edit + "\" is not KEY=VALUE");
  const std::string key = edit.substr(0, eq), value = edit.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed = toml::table{};
    parsed.insert("v", value);
  }
  toml::table* t = &root;
  size_t start = 0;
  for (size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
    const std::string part = key.substr(start, dot - start);
    if (!t->get(part)) t->insert(part, toml::table{});
    t = t->get(part)->as_table();
    if (!t) bad("set", key + ": " + part + " is not a table");
  }
  parsed.get("v")->visit([&](auto& v) { t->insert_or_assign(key.substr(start), std::move(v)); });
}

void make_file(const FileSpec& f, const fs::path& dir) {
  const fs::path path = dir / expand(f.path, dir);
  if (f.has_content) {
    spit(path, expand(f.content, dir));
  } else if (!f.from.empty()) {
    toml::table doc = toml::parse_file(kSource + "/" + f.from);
    for (const std::string& s : f.set) apply_set(doc, expand(s, dir));
    std::ostringstream os;
    os << doc << "\n";
    spit(path, os.str());
  } else {
    ASSERT_TRUE(fs::exists(path)) << f.path << ": nothing to edit (replace needs a file a step wrote)";
    const std::string before = slurp(path);
    const std::string after = std::regex_replace(before, std::regex(f.replace[0]), expand(f.replace[1], dir));
    ASSERT_NE(before, after) << f.path << ": " << f.replace[0] << " matches nothing";
    spit(path, after);
  }
}

// Every file under dir, relative, with '/' separators.
std::vector<std::string> files_under(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    out.push_back(fs::relative(it->path(), dir, ec).generic_string());
  }
  return out;
}

// '*' matches any run of characters.
bool glob(const std::string& pattern, const std::string& s) {
  size_t p = 0, i = 0, star = std::string::npos, mark = 0;
  while (i < s.size()) {
    if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = i;
    } else if (p < pattern.size() && pattern[p] == s[i]) {
      ++p;
      ++i;
    } else if (star != std::string::npos) {
      p = star + 1;
      i = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

// Path -> (size, mtime) of every file of the source tree but build directories and .git: what
// "no file outside DIR changed" is checked on (with the temporary directory's siblings).
std::map<std::string, std::pair<uintmax_t, long long>> snapshot(const fs::path& root) {
  std::map<std::string, std::pair<uintmax_t, long long>> out;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const std::string name = it->path().filename().string();
    if (it->is_directory(ec) && (name == ".git" || name.rfind("build", 0) == 0 || name == "out")) {
      it.disable_recursion_pending();
      continue;
    }
    struct stat st {};
    if (::lstat(it->path().c_str(), &st) == 0)
      out[it->path().string()] = {static_cast<uintmax_t>(st.st_size), static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec};
  }
  return out;
}

std::vector<std::string> siblings(const fs::path& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir.parent_path(), ec))
    if (e.path().filename().string().rfind(dir.filename().string(), 0) == 0) out.push_back(e.path().string());
  return out;
}

void expect_checks(const Checks& c, const fs::path& dir, const std::string& when) {
  const std::vector<std::string> files = files_under(dir);
  for (const std::string& p : c.exists) {
    const std::string pattern = expand(p, dir);
    EXPECT_TRUE(std::any_of(files.begin(), files.end(), [&](const std::string& f) { return glob(pattern, f); }))
        << when << ": " << p << " does not exist";
  }
  for (const std::string& p : c.absent) {
    const std::string pattern = expand(p, dir);
    for (const std::string& f : files) EXPECT_FALSE(glob(pattern, f)) << when << ": " << f << " exists (matches " << p << ")";
  }
  for (const auto& [p, text] : c.contains)
    EXPECT_NE(slurp(dir / expand(p, dir)).find(expand(text, dir)), std::string::npos) << when << ": " << p << " lacks " << text;
}

// gtest shows a case by its name, not its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class Hostile : public ::testing::TestWithParam<Case> {};

// Whether this build runs under AddressSanitizer (scripts/sanitize.sh), where the reference is
// tens of times slower.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

TEST_P(Hostile, Case) {
  const Case& c = GetParam();
  if (kSanitized && !c.sanitized) GTEST_SKIP() << "too long under the sanitizers (sanitized = false)";
  if (!c.issue.empty()) RecordProperty("issue", c.issue);
  TempDir tmp("tippe-hostile");
  const fs::path dir = fs::canonical(tmp.path());
  for (const FileSpec& f : c.files) ASSERT_NO_FATAL_FAILURE(make_file(f, dir));
  const auto source_before = snapshot(kSource);
  const auto siblings_before = siblings(dir);
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  for (size_t k = 0; k < c.steps.size(); ++k) {
    const Step& s = c.steps[k];
    for (const FileSpec& f : s.files) ASSERT_NO_FATAL_FAILURE(make_file(f, dir));
    std::vector<std::string> argv = {kBinary};
    std::string shown = "tippe";
    for (const std::string& a : s.args) {
      argv.push_back(expand(a, dir));
      shown += " " + a;
    }
    const fs::path out = dir / (".step" + std::to_string(k) + ".out"), err = dir / (".step" + std::to_string(k) + ".err");
    const ChildExit e = wait_process_within(spawn_process(argv, out, err), s.timeout);
    const std::string so = slurp(out), se = slurp(err);
    fs::remove(out);
    fs::remove(err);
    const std::string context = "step " + std::to_string(k) + ": " + shown + "\nstdout:\n" + so + "\nstderr:\n" + se;
    EXPECT_FALSE(e.timed_out) << "hung (killed after " << s.timeout << " s)\n" << context;
    EXPECT_EQ(e.code, s.exit) << context;
    if (!s.stderr_text.empty()) {
      EXPECT_NE(se.find(expand(s.stderr_text, dir)), std::string::npos) << context;
    }
    if (!s.stdout_text.empty()) {
      EXPECT_NE(so.find(expand(s.stdout_text, dir)), std::string::npos) << context;
    }
    if (!s.internal) {
      EXPECT_EQ(se.find("error: internal"), std::string::npos) << "an internal error is a bug\n" << context;
    }
    expect_checks(s.checks, dir, "after step " + std::to_string(k));
  }
  fs::current_path(cwd);

  expect_checks(c.checks, dir, "after the last step");
  const std::vector<std::string> files = files_under(dir);
  if (c.temporaries) {
    for (const std::string& f : files) EXPECT_FALSE(glob("*.tmp.*", f)) << f << ": a temporary file left behind";
  }
  EXPECT_EQ(siblings(dir), siblings_before) << "files made beside the case's directory";
  const auto source_after = snapshot(kSource);
  for (const auto& [path, stat] : source_after) {
    const auto it = source_before.find(path);
    EXPECT_TRUE(it != source_before.end() && it->second == stat) << path << " changed or appeared";
  }
  for (const auto& [path, stat] : source_before) EXPECT_TRUE(source_after.count(path)) << path << " disappeared";
}

std::vector<Case> all_cases() {
  try {
    return load_cases();
  } catch (const std::exception& e) {
    // One case that fails with the reason, rather than a suite that silently has none.
    Case c;
    c.name = "cases_file_is_malformed";
    Step s;
    s.args = {"--bad-cases-file"};
    s.exit = -100;
    s.stderr_text = e.what();
    c.steps.push_back(s);
    return {c};
  }
}

INSTANTIATE_TEST_SUITE_P(Table, Hostile, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace

}  // namespace test_hostile
