// Scene -> JSON: every field of a scene, its mass properties and engine tables, as run records carry it.
#include "harness/io/scene_io.h"

#include <variant>

namespace tippe {

nlohmann::json setting_to_json(const SettingValue& value) {
  return std::visit([](const auto& v) { return nlohmann::json(v); }, value);
}

nlohmann::json scene_to_json(const Scene& s) {
  using nlohmann::json;
  json engines = json::object();
  for (const auto& [engine, table] : s.engines) {
    json t = json::object();
    for (const auto& [k, v] : table) t[k] = setting_to_json(v);
    engines[engine] = t;
  }
  json out{
      {"name", s.name},
      {"description", s.description},
      {"source_file", s.source_file},
      {"content_hash", s.content_hash},
      {"gravity", s.gravity},
      {"body",
       {{"sphere_radius", s.body.sphere_radius},
        {"stem_radius", s.body.stem_radius},
        {"stem_length", s.body.stem_length},
        {"truncation_height", s.body.truncation_height},
        {"density", s.body.density},
        {"mass_model", to_string(s.body.mass_model)}}},
      {"mass_properties",
       {{"mass", s.mass.mass},
        {"com_offset", s.mass.com_offset},
        {"inertia_transverse", s.mass.inertia_transverse},
        {"inertia_axial", s.mass.inertia_axial}}},
      {"contact",
       {{"friction", to_string(s.contact.friction)},
        {"mu", s.contact.mu},
        {"k", s.contact.k},
        {"drilling", s.contact.drilling},
        {"drilling_law", to_string(s.contact.drilling_law)},
        {"stem", s.contact.stem},
        {"flight", s.contact.flight}}},
      {"initial",
       {{"tilt", s.initial.tilt},
        {"omega_given", s.initial.omega_given},
        {"spin", s.initial.spin},
        {"omega", s.initial.omega_B},
        {"velocity_given", s.initial.velocity_given},
        {"velocity", s.initial.velocity},
        {"omega_along_contact", s.initial.omega_along_contact},
        {"height", s.initial.height}}},
      {"run",
       {{"duration", s.run.duration},
        {"sample_interval", s.run.sample_interval},
        {"rtol", s.run.rtol},
        {"atol", s.run.atol},
        {"method", s.run.method},
        {"self_check", s.run.self_check}}},
      {"engines", engines},
  };
  // Written only when used, so that the JSON (and the physics hash) of every other scene stays as it was.
  if (s.initial.orientation_given) out["initial"]["orientation"] = s.initial.orientation;
  if (s.initial.position[0] != 0.0 || s.initial.position[1] != 0.0) out["initial"]["position"] = s.initial.position;
  if (!s.notes.empty()) out["notes"] = s.notes;
  // Absent means "total", the one rule of the records written before the key existed; every
  // other rule, the default "stored" too, is named.
  if (s.run.energy_gain_rule != "total") out["run"]["energy_gain_rule"] = s.run.energy_gain_rule;
  return out;
}

}  // namespace tippe
