// The analysis of a user's MuJoCo model as a tippe top, shared by its two files: checking what the reference can represent (mujoco_import.cpp) and deriving the top from it (mujoco_import_derive.cpp).
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <utility>

#include "engines/mujoco/mujoco_top.h"

namespace tippe::mjcf_import_detail {

// A number in a message: 12 significant digits, whatever the locale.
std::string g(double v);
// A MuJoCo object's name, or "#id" when it has none.
std::string name_of(const mjModel* m, mjtObj type, int id);

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// One model read as a top: each step fills `out` or fails with a message naming the file and body.
class Analyser {
 public:
  Analyser(const mjModel* m, std::string label) : m_(m), label_(std::move(label)) {}

  [[noreturn]] void fail(const std::string& why) const;
  void check_options() const;

  MjcfTopImport run(const std::string& body_name, const std::string& key_name, MjTopIds* ids);

 private:
  // What the reference can represent: the top's body, the model around it, the floor and the geoms.
  void find_body(const std::string& wanted);
  void check_model();
  void find_geoms(MjcfTopImport& out);
  // The top derived from the checked model: mass and axis, stem, contact law, start.
  void mass_and_axis(MjcfTopImport& out);
  Vec3 stem_direction() const;
  void stem_geometry(MjcfTopImport& out);
  mjContact probe(int geom, bool upside_down) const;
  Quat q_FB_inv() const { return q_FB_.conjugate(); }
  void contact(MjcfTopImport& out);
  void start(MjcfTopImport& out, const std::string& key_name);

  const mjModel* m_;
  std::string label_;
  int body_ = -1, joint_ = -1, ball_ = -1, stem_ = -1, floor_ = -1;
  Vec3 G_ = Vec3::Zero(), O_ = Vec3::Zero(), e_ = Vec3::UnitZ();
  double R_ = 0.0, stem_length_ = 0.0;
  Quat q_FB_ = Quat::Identity();
};

}  // namespace tippe::mjcf_import_detail
