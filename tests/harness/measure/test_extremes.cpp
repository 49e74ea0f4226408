// Tests of the extremes battery: classified sweep records, the stability map, the shipped battery files, and the short battery end to end.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "analytic/initial_state.h"
#include "analytic/observables.h"
#include "analytic/reference_model.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"
#include "harness/sweep/sweep.h"
#include "tests/support/files.h"
#include "harness/report/sweep_analysis.h"

namespace test_extremes {

namespace fs = std::filesystem;
using namespace tippe;
using nlohmann::json;

namespace {

const std::string kSource = TIPPE_SOURCE_DIR;
const std::string kBinary = std::string(TIPPE_BINARY_DIR) + "/tippe";

SweepRecord point(const std::string& scene, long long scene_index, const std::string& setup, long long ladder_index,
                  double dt, const std::string& cls, double cls_time, bool inverts) {
  SweepRecord r;
  r.point_id = scene + setup + std::to_string(ladder_index);
  r.scene = scene;
  r.scene_index = scene_index;
  r.setup = setup;
  r.engine = setup;
  r.ladder_key = "engines." + setup + ".timestep";
  r.ladder_value = dt;
  r.ladder_index = ladder_index;
  r.status = cls == "unphysical" ? "ok" : cls;
  r.run_class = cls;
  r.class_time = cls_time;
  r.class_reason = cls == "ok" ? "" : "because";
  r.reference_inversion_time = std::nullopt;  // the reference does not invert
  r.inversion_time = inverts ? std::optional<double>(1.0) : std::nullopt;
  r.metrics.inversion_event = inverts ? "engine_only" : "neither";
  SweepRecord::ReferenceRun f;
  f.status = "ok";
  f.method = "bulirsch_stoer";
  f.run_class = "ok";
  f.rtol = 1e-10;
  f.steps = 100;
  f.energy_initial = 2.0;
  f.energy_final = 1.5;
  f.jellett_max_relative_drift = 1e-13;
  r.reference = f;
  return r;
}

}  // namespace

TEST(ExtremesRecords, ClassAndReferenceRoundTrip) {
  SweepRecord r = point("spin_high", 0, "bullet", 2, 1e-3, "clamped", 0.25, false);
  const SweepRecord back = sweep_record_from_json(json::parse(to_jsonl(r)));
  EXPECT_EQ(back.run_class, "clamped");
  EXPECT_EQ(back.class_time, 0.25);
  EXPECT_EQ(back.class_reason, "because");
  ASSERT_TRUE(back.reference.has_value());
  EXPECT_EQ(back.reference->method, "bulirsch_stoer");
  EXPECT_EQ(back.reference->energy_final, 1.5);
  EXPECT_EQ(to_jsonl(back), to_jsonl(r));
}

// Records written before classification existed still read, with the class their status implies.
TEST(ExtremesRecords, OldRecordsTakeTheirClassFromTheStatus) {
  json j = to_json(point("k_high", 0, "ode", 0, 0.1, "diverged", 0.5, false));
  j.erase("class");
  j.erase("reference");
  SweepRecord back = sweep_record_from_json(j);
  EXPECT_EQ(back.run_class, "diverged");
  EXPECT_TRUE(std::isnan(back.class_time));
  EXPECT_FALSE(back.reference.has_value());
  j["status"] = "unphysical";
  EXPECT_EQ(sweep_record_from_json(j).run_class, "failed");
  // Records are input: a status outside the known set is refused, not read as "failed".
  j["status"] = "some_new_status";
  EXPECT_ANY_THROW(sweep_record_from_json(j));
}

TEST(ExtremesReport, StabilityMapHasOneCellPerPointColouredByClass) {
  std::vector<SweepRecord> rs = {
      point("spin_high", 0, "ode", 0, 1e-1, "diverged", 0.125, false),
      point("spin_high", 0, "ode", 1, 1e-2, "unphysical", 0.5, false),
      point("spin_high", 0, "ode", 2, 1e-3, "ok", std::nan(""), true),  // inverts, the reference does not
      point("mu_high", 1, "ode", 0, 1e-1, "clamped", 0.1, false),
      point("mu_high", 1, "ode", 2, 1e-3, "ok", std::nan(""), false),
  };
  const std::string md = render_sweep_markdown(rs);
  EXPECT_NE(md.find("## Stability map"), std::string::npos);
  EXPECT_NE(md.find("| scene \\ engines.ode.timestep | 0.1 | 0.01 | 0.001 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| spin_high | diverged at 0.125 | unphysical at 0.5 | ok, regime differs |"), std::string::npos)
      << md;
  // mu_high has no point at 0.01: the cell says so instead of shifting the row.
  EXPECT_NE(md.find("| mu_high | clamped at 0.1 | - | ok |"), std::string::npos) << md;
  // The reference's own run: |E_end - E0| / E0 = 0.5 / 2.
  EXPECT_NE(md.find("| spin_high | bulirsch_stoer | 1e-10 | ok | ok | 100 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 0.25 | 1e-13 |"), std::string::npos) << md;

  TempDir dir{"tippe-extremes"};
  write_sweep_report(dir.path().string(), rs, false);
  const std::string html = slurp(dir.path() / "index.html");
  for (const char* cls : {"c-diverged", "c-unphysical", "c-regime", "c-clamped", "c-ok"})
    EXPECT_NE(html.find(std::string("<td class=\"") + cls + "\">"), std::string::npos) << cls;
}

// Every scene of the battery loads, and each sweep file of the battery expands to its points.
TEST(ExtremesFiles, BatteryScenesAndSweepsLoad) {
  size_t scenes = 0;
  for (const auto& e : fs::directory_iterator(kSource + "/harness/scenes/extremes")) {
    if (e.path().extension() != ".toml") continue;
    EXPECT_NO_THROW(load_scene(e.path().string())) << e.path();
    ++scenes;
  }
  EXPECT_GE(scenes, 13u);
  for (const char* f : {"extremes.toml", "extremes-long.toml", "extremes-short.toml"}) {
    const SweepPlan plan = load_sweep(kSource + "/harness/sweeps/" + f);
    EXPECT_FALSE(plan.points.empty()) << f;
  }
  // The battery covers engine time steps from 1e-6 to 1e-1.
  const SweepPlan full = load_sweep(kSource + "/harness/sweeps/extremes.toml");
  double lo = 1, hi = 0;
  for (const SweepSetup& s : full.spec.setups)
    if (s.engine != "analytic")
      for (double v : s.ladder_values) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_EQ(lo, 1e-6);
  EXPECT_EQ(hi, 1e-1);
}

// The CI variant of the battery end to end: every point classified, the reference itself ok and
// keeping Jellett's integral (which holds for the viscous and Coulomb laws on one surface) to
// 1e-9 on every extreme, and the stability map in the report.
TEST(ExtremesBattery, ShortVariantClassifiesEveryPoint) {
  TempDir dir{"tippe-extremes"};
  const fs::path out = dir.path() / "out";
  const std::string cmd = "cd '" + kSource + "' && '" + kBinary + "' sweep harness/sweeps/extremes-short.toml --out '" +
                          out.string() + "' --jobs 2 > '" + (dir.path() / "log").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir.path() / "log");
  const RecordsFile f = read_records((out / "records.jsonl").string());
  const SweepPlan plan = load_sweep(kSource + "/harness/sweeps/extremes-short.toml");
  ASSERT_EQ(f.records.size(), plan.points.size());
  const std::set<std::string> classes = {"ok", "diverged", "unphysical", "clamped", "failed", "contact_lost"};
  std::set<std::string> scenes;
  for (const SweepRecord& r : f.records) {
    EXPECT_EQ(classes.count(r.run_class), 1u) << r.run_class;
    if (r.run_class != "ok") {
      EXPECT_FALSE(r.class_reason.empty()) << r.scene << " " << r.setup;
    }
    ASSERT_TRUE(r.reference.has_value());
    EXPECT_EQ(r.reference->status, "ok") << r.scene;
    EXPECT_EQ(r.reference->run_class, "ok") << r.scene;
    // 1e-9: the reference keeps J to < 1e-11 on every shipped scene at rtol 1e-10; 100x margin.
    EXPECT_LT(r.reference->jellett_max_relative_drift, 1e-9) << r.scene;
    if (r.engine == "analytic") {
      EXPECT_EQ(r.run_class, "ok") << r.scene << " rtol " << r.ladder_value;
    }
    scenes.insert(r.scene);
  }
  EXPECT_EQ(scenes.size(), plan.scenes.size());
  const std::string md = slurp(out / "report.md");
  EXPECT_NE(md.find("## Stability map"), std::string::npos);
  EXPECT_NE(md.find("### The reference on each scene"), std::string::npos);
}

// A top started beyond the switching tilt (already inverted) rests on its stem tip, not on a
// ball whose stem would be deep in the floor; the reference starts in stem contact carrying the
// weight. Tolerances: the gap is a sum of terms of size R (1e-12 R is round-off); the stem's
// normal force balances M g up to the centripetal and tilt terms of a spinning start (10 %).
TEST(ExtremesStart, InvertedStartRestsOnTheStem) {
  const Scene scene = load_scene(kSource + "/harness/scenes/extremes/tilt_near_pi.toml");
  const BodyModel m = BodyModel::from_scene(scene);
  const BodyState x0 = scene_initial_state(scene);
  ASSERT_EQ(lower_surface(m, x0.q_WB), Surface::Stem);
  EXPECT_NEAR(surface_gap(m, x0, Surface::Stem), 0.0, 1e-12 * m.R);
  EXPECT_GT(surface_gap(m, x0, Surface::Ball), 0.01 * m.R);
  // The tip's centre P moves horizontally at the start.
  const Vec3 w_W = x0.q_WB * x0.w_B;
  const Vec3 v_P = x0.v_WG + w_W.cross(m.z_P() * (x0.q_WB * Vec3::UnitZ()));
  EXPECT_NEAR(v_P.z(), 0.0, 1e-12 * (1.0 + w_W.norm() * m.R));
  ReferenceModel ref(scene);
  ASSERT_EQ(ref.status(), ReferenceStatus::Ok) << ref.status_detail();
  EXPECT_EQ(ref.contact_surface(), Surface::Stem);
  EXPECT_NEAR(ref.forces().normal[1], m.M * m.g, 0.1 * m.M * m.g);
  EXPECT_EQ(ref.forces().normal[0], 0.0);
}

// The tilt keeps its digits at both ends (it was acos of e_Z.z, which reads a tilt of 1e-9 as 0:
// cos = 1 - 5e-19 rounds to 1). 1e-15 relative: a few rounding errors of the rotation.
TEST(ExtremesStart, TiltIsExactNearVerticalAndInverted) {
  for (double t : {1e-12, 1e-9, 1e-4, 0.1, 1.5, 3.0}) {
    EXPECT_NEAR(tilt(Quat(Eigen::AngleAxisd(t, Vec3::UnitX()))), t, 1e-15 * t) << t;
    const double u = 3.14159265358979323846 - t;
    EXPECT_NEAR(tilt(Quat(Eigen::AngleAxisd(u, Vec3::UnitX()))), u, 1e-15 * u) << u;
  }
  EXPECT_EQ(tilt(Quat::Identity()), 0.0);
}

}  // namespace test_extremes
