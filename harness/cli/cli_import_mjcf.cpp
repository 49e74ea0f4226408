// `tippe import-mjcf`: a scene from a user's own MuJoCo model, whose MuJoCo run is that model as written.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <locale>
#include <memory>
#include <sstream>

#include "harness/cli/cli.h"
#include "harness/library/verbs.h"
#include "harness/io/output_dir.h"
#include "engines/core/settings.h"
#include "harness/io/scene_io.h"

namespace tippe::cli {

namespace {

namespace fs = std::filesystem;

struct ImportOptions {
  std::string model;
  std::string body;
  std::string keyframe;
  std::string out;
  double duration = 5.0;
  double sample_interval = 0.0;  // 0: the larger of 1 ms and the model's timestep
};

int import_mjcf(const ImportOptions& o) {
  MjcfSceneRequest request;
  request.model = o.model;
  request.body = o.body;
  request.keyframe = o.keyframe;
  request.out = o.out;
  request.duration = o.duration;
  request.sample_interval = o.sample_interval;
  const MjcfScene scene = import_mjcf_scene(request);
  const MjcfTopImport& top = scene.top;
  write_result_file(o.out, scene.text);

  const BodyState& x = top.start;
  const double tilt = std::atan2((x.q_WB * Vec3::UnitZ()).head<2>().norm(), (x.q_WB * Vec3::UnitZ()).z());
  std::printf("model          %s, body '%s', %s (MuJoCo %s)\n", o.model.c_str(), top.body.c_str(),
              top.keyframe_index >= 0 ? ("keyframe '" + top.keyframe + "'").c_str() : "qpos0", top.mujoco_version.c_str());
  std::printf("mass           M = %.10g, d = %.10g, A = %.10g, C = %.10g\n", top.mass.mass, top.mass.com_offset,
              top.mass.inertia_transverse, top.mass.inertia_axial);
  if (top.stem)
    std::printf("geometry       R = %.10g, stem %s r = %.10g, l = %.10g\n", top.geometry.sphere_radius, top.stem_type.c_str(),
                top.geometry.stem_radius, top.geometry.stem_length);
  else
    std::printf("geometry       R = %.10g, no stem\n", top.geometry.sphere_radius);
  std::printf("contact        %s, mu = %.10g, drilling = %.10g (condim %d)\n", to_string(top.contact.friction),
              top.contact.mu, top.contact.drilling, top.condim);
  std::printf("gravity        %.10g\n", top.gravity);
  std::printf("start          tilt %.10g rad, omega_B = (%.10g, %.10g, %.10g), v_G = (%.10g, %.10g, %.10g)\n", tilt,
              x.w_B.x(), x.w_B.y(), x.w_B.z(), x.v_WG.x(), x.v_WG.y(), x.v_WG.z());
  for (const auto& n : top.notes) std::printf("note           %s\n", n.c_str());
  std::printf("wrote          %s\n", o.out.c_str());
  return 0;
}

}  // namespace

Command setup_import_mjcf(CLI::App& app) {
  auto o = std::make_shared<ImportOptions>();
  CLI::App* sub = app.add_subcommand(
      "import-mjcf", "Write a scene from your own MuJoCo model (MJCF); its MuJoCo run is that model as written");
  sub->add_option("model", o->model, "MuJoCo model (MJCF XML)")->required();
  sub->add_option("--body", o->body, "The top's body (default: the one body with a free joint)");
  sub->add_option("--keyframe", o->keyframe, "The start (default: the first keyframe, else qpos0 at rest)");
  sub->add_option("--out", o->out, "Scene file to write (TOML)")->required();
  sub->add_option("--duration", o->duration, "Run duration in the scene, s (default 5)");
  sub->add_option("--sample-interval", o->sample_interval, "Sample interval in the scene, s (default: the larger of 1 ms and the model's timestep)");
  return {sub, [o] { return import_mjcf(*o); }};
}

}  // namespace tippe::cli
