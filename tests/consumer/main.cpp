// Runs the reference on a scene through the installed library and prints the summary's members, one "key value" a line.
#include <cstdio>
#include <string>
#include <vector>

#include <tippe/tippe.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCENE.toml [KEY=VALUE...]\n");
    return 2;
  }
  const std::vector<std::string> overrides(argv + 2, argv + argc);
  try {
    const tippe::RunSummary s = tippe::run_scene_file(argv[1], overrides);
    // 17 significant digits: every double reads back as itself, so the test can ask for equality.
    std::printf("scene %s\n", s.scene.c_str());
    std::printf("status %s\n", s.status.c_str());
    std::printf("samples %lld\n", s.samples);
    if (s.inversion_time) std::printf("inversion_time %.17g\n", *s.inversion_time);
    std::printf("final_time %.17g\n", s.final_time);
    std::printf("final_tilt %.17g\n", s.final_tilt);
    std::printf("energy_initial %.17g\n", s.energy_initial);
    std::printf("energy_final %.17g\n", s.energy_final);
    std::printf("jellett_initial %.17g\n", s.jellett_initial);
    std::printf("min_normal_force %.17g\n", s.min_normal_force);
    std::printf("mass %.17g\n", s.mass_properties.mass);
    std::printf("events %zu\n", s.events.size());
    for (const tippe::SummaryEvent& e : s.events) std::printf("event %s %.17g\n", e.name.c_str(), e.time);
  } catch (const tippe::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
