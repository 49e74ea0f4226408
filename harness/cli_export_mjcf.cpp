// `tippe export-mjcf`: the MuJoCo model of a scene, for inspection in MuJoCo's own tools.
#include <iostream>
#include <memory>

#include "adapters.h"
#include "cli.h"
#include "records.h"
#include "scene_io.h"

namespace tippe::cli {

namespace {

struct ExportOptions {
  std::string scene;
  std::string out;
  std::vector<std::string> sets;
};

int export_mjcf(const ExportOptions& o) {
  const Scene scene = load_scene(o.scene, o.sets);
  std::string text;
  try {
    text = mujoco_mjcf(scene);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (text.empty()) throw std::runtime_error("mujoco_mjcf produced no model");
  if (o.out.empty()) {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw std::runtime_error("cannot write to stdout");
  } else {
    write_file_atomic(o.out, text);
  }
  return 0;
}

}  // namespace

Command setup_export_mjcf(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* sub = app.add_subcommand("export-mjcf", "Write the scene's MuJoCo model (MJCF)");
  add_scene_options(sub, o->scene, o->sets);
  sub->add_option("--out", o->out, "Output file (default stdout)");
  return {sub, [o] { return export_mjcf(*o); }};
}

}  // namespace tippe::cli
