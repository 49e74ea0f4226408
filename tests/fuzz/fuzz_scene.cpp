// libFuzzer target: arbitrary bytes as a scene file through parse_scene_text; any exception but SceneError is a crash.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace {

// Input layout: SCENE_TEXT [ '\0' OVERRIDE ]... The scene text ends at the first NUL byte (a
// scene file cannot contain one anyway) and every NUL-separated piece after it is a --set
// override, so the override path is fuzzed with arbitrary bytes too; the shipped scenes, which
// have no NUL, are valid seeds as they are.
struct Input {
  std::string text;
  std::vector<std::string> overrides;
};

Input split(const std::string& bytes) {
  Input in;
  const size_t nul = bytes.find('\0');
  in.text = bytes.substr(0, nul);
  for (size_t pos = nul; pos != std::string::npos && in.overrides.size() < 16;) {
    const size_t next = bytes.find('\0', pos + 1);
    in.overrides.push_back(bytes.substr(pos + 1, next == std::string::npos ? std::string::npos : next - pos - 1));
    pos = next;
  }
  return in;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Input in = split(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const tippe::Scene s = tippe::parse_scene_text(in.text, "fuzz/input.toml", in.overrides);
    // What every run does next with an accepted scene: its record is JSON, so the scene must
    // serialise without throwing (nlohmann::json throws on strings that are not UTF-8).
    (void)tippe::scene_to_json(s).dump();
  } catch (const tippe::SceneError&) {
    // The one documented failure: a message naming the file and key.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_scene: unexpected exception: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_scene: unexpected non-standard exception\n");
    std::abort();
  }
  return 0;
}
