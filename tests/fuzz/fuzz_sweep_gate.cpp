// libFuzzer target: arbitrary bytes as a sweep file and as a gate file (load_sweep, load_gate_file); any exception but SceneError is a crash.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "harness/gating/gate.h"
#include "harness/io/scene_io.h"
#include "harness/sweep/sweep.h"

namespace fs = std::filesystem;

namespace {

// The loaders read files and resolve scene paths against them, so each input is written where a
// shipped sweep or gate file would be: DIR/harness/{sweeps,gates}/input.toml, with
// DIR/harness/scenes a link to the real scenes. The shipped files are then valid seeds as they are.
struct Layout {
  fs::path sweep, gate;
  Layout() {
    std::string t = (fs::temp_directory_path() / "tippe-fuzz-XXXXXX").string();
    if (!::mkdtemp(t.data())) std::abort();
    const fs::path root = fs::path(t) / "harness";
    fs::create_directories(root / "sweeps");
    fs::create_directories(root / "gates");
    fs::create_directory_symlink(fs::path(TIPPE_SOURCE_DIR) / "harness" / "scenes", root / "scenes");
    sweep = root / "sweeps" / "input.toml";
    gate = root / "gates" / "input.toml";
  }
};

void write(const fs::path& p, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

template <class F>
void expect_only_scene_errors(const char* what, F&& load) {
  try {
    load();
  } catch (const tippe::SceneError&) {
    // The one documented failure: a message naming the file and key.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_sweep_gate: %s: unexpected exception: %s\n", what, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_sweep_gate: %s: unexpected non-standard exception\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Layout layout;
  write(layout.sweep, data, size);
  write(layout.gate, data, size);
  expect_only_scene_errors("sweep", [&] { (void)tippe::load_sweep(layout.sweep.string()); });
  expect_only_scene_errors("gate", [&] { (void)tippe::load_gate_file(layout.gate.string()); });
  return 0;
}
