// `tippe info`: a scene's mass properties, the inversion condition and every engine's settings in force.
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/cli.h"
#include "mass_properties.h"
#include "io/scene_io.h"
#include "simulator.h"

namespace tippe::cli {

namespace {

struct InfoOptions {
  std::string scene;
  std::vector<std::string> sets;
};

std::string setting_text(const SettingValue& v) { return setting_to_json(v).dump(); }

}  // namespace

std::string inversion_condition_text(double alpha, double ratio) {
  char buf[256];
  // The same test as inversion_possible: 1 - alpha < A/C < 1 + alpha, each side said as it holds.
  if (1 - alpha < ratio && ratio < 1 + alpha)
    std::snprintf(buf, sizeof buf, "yes: 1 - alpha = %.6g < A/C = %.6g < 1 + alpha = %.6g", 1 - alpha, ratio,
                  1 + alpha);
  else if (ratio >= 1 + alpha)
    std::snprintf(buf, sizeof buf, "no: A/C = %.6g >= 1 + alpha = %.6g (inversion needs 1 - alpha < A/C < 1 + alpha)",
                  ratio, 1 + alpha);
  else
    std::snprintf(buf, sizeof buf, "no: A/C = %.6g <= 1 - alpha = %.6g (inversion needs 1 - alpha < A/C < 1 + alpha)",
                  ratio, 1 - alpha);
  return buf;
}

namespace {

int info(const InfoOptions& o) {
  const Scene s = load_scene(o.scene, o.sets);
  const MassProperties& m = s.mass;
  const double R = s.body.sphere_radius;
  const double alpha = m.com_offset / R, ratio = m.inertia_transverse / m.inertia_axial;

  std::printf("scene              %s (%s, hash %s)\n", s.name.c_str(), s.source_file.c_str(), s.content_hash.c_str());
  if (!s.description.empty()) std::printf("description        %s\n", s.description.c_str());
  for (const auto& n : s.notes) std::printf("note               %s\n", n.c_str());
  std::printf("geometry           R = %.10g, r = %.10g, l = %.10g, h = %.10g%s\n", R, s.body.stem_radius,
              s.body.stem_length, s.body.truncation_height, s.contact.stem ? "" : " (no stem contact)");
  if (s.body.mass_model == MassModel::Given)
    std::printf("mass model         given\n");
  else
    std::printf("mass model         %s, density %.10g\n", to_string(s.body.mass_model), s.body.density);
  std::printf("mass M             %.10g\n", m.mass);
  std::printf("com offset d       %.10g\n", m.com_offset);
  std::printf("inertia A, C       %.10g, %.10g\n", m.inertia_transverse, m.inertia_axial);
  std::printf("alpha = d/R        %.10g\n", alpha);
  std::printf("A/C                %.10g\n", ratio);
  std::printf("can invert         %s\n", inversion_condition_text(alpha, ratio).c_str());
  std::printf("contact            %s, mu = %g, k = %g, drilling = %g (%s), flight %s\n", to_string(s.contact.friction),
              s.contact.mu, s.contact.k, s.contact.drilling, to_string(s.contact.drilling_law), s.contact.flight ? "on" : "off");
  std::printf("run                duration %g, sample interval %g, rtol %g, atol %g\n", s.run.duration,
              s.run.sample_interval, s.run.rtol, s.run.atol);

  for (const std::string& engine : available_engines()) {
    std::printf("\n[%s]\n", engine.c_str());
    if (auto it = s.engines.find(engine); it != s.engines.end() && !it->second.empty()) {
      std::printf("  from the scene:");
      for (const auto& [k, v] : it->second) std::printf(" %s=%s", k.c_str(), setting_text(v).c_str());
      std::printf("\n");
    }
    // The settings in force are what the simulator itself reports, defaults included.
    try {
      const auto sim = make_simulator(engine, s);
      for (const auto& [k, v] : sim->settings()) std::printf("  %s = %s\n", k.c_str(), v.c_str());
    } catch (const std::exception& e) {
      std::printf("  (not available: %s)\n", e.what());
    }
  }
  return 0;
}

}  // namespace

Command setup_info(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* sub = app.add_subcommand("info", "Show a scene's mass properties, inversion condition and engine settings");
  add_scene_options(sub, o->scene, o->sets);
  return {sub, [o] { return info(*o); }};
}

}  // namespace tippe::cli
