// `tippe export-mjcf`: the MuJoCo model of a scene, for inspection in MuJoCo's own tools.
#include <iostream>
#include <memory>

#include "harness/cli/cli.h"
#include "harness/io/output_dir.h"
#include "engines/mujoco/mujoco_api.h"
#include "harness/records/records.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe::cli {

namespace {

struct ExportOptions {
  std::string scene;
  std::string out;
  std::vector<std::string> sets;
  bool force = false;
};

int export_mjcf(const ExportOptions& o) {
  const Scene scene = load_scene(o.scene, o.sets);
  // The model written over the scene (or over the scene's own model) would replace it.
  if (!o.out.empty()) refuse_output_over_inputs(o.out, scene_input_files(scene));
  std::string text;
  try {
    text = mujoco_api().mjcf(scene);
  } catch (const std::invalid_argument& e) {
    throw UsageError(scene.source_file + ": " + e.what());
  }
  if (text.empty()) throw std::runtime_error("mujoco_mjcf produced no model");
  // A model that lacks part of the scene's physics is refused, or written with its gaps said in
  // the file and on stderr (--force): a user opening it must not take it for the scene.
  const std::vector<std::string> missing = mujoco_api().mjcf_missing(scene);
  if (!missing.empty() && !o.force) {
    std::string why;
    for (const auto& m : missing) why += (why.empty() ? "" : "; ") + m;
    throw UsageError(scene.source_file + ": contact.friction: the MuJoCo model cannot carry " + why +
                     " (give --force to write it anyway, with this said in the file)");
  }
  if (!missing.empty()) {
    std::string comment = "<!-- NOT THE WHOLE SCENE: this model lacks";
    for (const auto& m : missing) {
      // "--" may not appear inside an XML comment.
      std::string safe = m;
      for (size_t p = safe.find("--"); p != std::string::npos; p = safe.find("--")) safe.replace(p, 2, "- -");
      comment += "\n     - " + safe;
      std::cerr << "tippe: warning: the exported model lacks " << m << "\n";
    }
    comment += " -->\n";
    const size_t at = text.find('\n', text.find("<mujoco"));
    text.insert(at == std::string::npos ? text.size() : at + 1, comment);
  }
  if (o.out.empty()) {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw std::runtime_error("cannot write to stdout");
  } else {
    write_result_file(o.out, text);
  }
  return 0;
}

}  // namespace

Command setup_export_mjcf(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* sub = app.add_subcommand("export-mjcf", "Write the scene's MuJoCo model (MJCF)");
  add_scene_options(sub, o->scene, o->sets);
  sub->add_option("--out", o->out, "Output file (default stdout)");
  sub->add_flag("--force", o->force,
                "Write the model even when it lacks part of the scene's physics (said in an XML comment and on stderr)");
  return {sub, [o] { return export_mjcf(*o); }};
}

}  // namespace tippe::cli
