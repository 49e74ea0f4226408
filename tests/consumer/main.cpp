// Runs the reference on a scene through the installed library and prints every field of the summary, one "key value" a line, walking the summary's field list (tippe::visit).
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <tippe/tippe.h>

namespace {

// Prints a field as "KEY VALUE" (a part's fields as "PART.KEY VALUE"): doubles with 17
// significant digits, so that every one reads back as itself and the test can ask for equality;
// "null" for an absent value.
struct Printer {
  std::string prefix;

  void operator()(const char* key, const std::string& v) const { line(key, v); }
  void operator()(const char* key, double v) const { line(key, number(v)); }
  void operator()(const char* key, long long v) const { line(key, std::to_string(v)); }
  void operator()(const char* key, bool v) const { line(key, v ? "true" : "false"); }
  void operator()(const char* key, const std::optional<double>& v) const { line(key, v ? number(*v) : "null"); }
  void operator()(const char* key, const std::vector<std::string>& v) const {
    line(key, std::to_string(v.size()));
    for (size_t i = 0; i < v.size(); ++i) line((std::string(key) + "." + std::to_string(i)).c_str(), v[i]);
  }
  void operator()(const char* key, const std::map<std::string, std::string>& v) const {
    for (const auto& [k, x] : v) line((std::string(key) + "." + k).c_str(), x);
  }
  void operator()(const char* key, const std::vector<tippe::SummaryEvent>& events) const {
    line(key, std::to_string(events.size()));
    for (const tippe::SummaryEvent& e : events) std::printf("event %s %.17g\n", e.name.c_str(), e.time);
  }
  template <class Part>
  void operator()(const char* key, const std::optional<Part>& part) const {
    if (part) (*this)(key, *part);
    else line(key, "null");
  }
  template <class Part, class = std::enable_if_t<std::is_class_v<Part>>>
  void operator()(const char* key, const Part& part) const {
    tippe::visit(part, Printer{prefix + key + "."});
  }

  void line(const char* key, const std::string& value) const {
    std::printf("%s%s %s\n", prefix.c_str(), key, value.c_str());
  }
  static std::string number(double v) {
    char s[40];
    std::snprintf(s, sizeof s, "%.17g", v);
    return s;
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCENE.toml [KEY=VALUE...]\n");
    return 2;
  }
  const std::vector<std::string> overrides(argv + 2, argv + argc);
  try {
    const tippe::RunSummary s = tippe::run_scene_file(argv[1], overrides);
    tippe::visit(s, Printer{});
  } catch (const tippe::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
