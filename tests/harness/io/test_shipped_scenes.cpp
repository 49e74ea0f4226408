// The reference on every shipped scene: which regime each run ends in, with its evidence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "analytic/reference_model.h"
#include "harness/io/scene_io.h"
#include "harness/scene/resolve.h"

namespace tippe::test_shipped_scenes {
namespace {

std::vector<std::string> shipped_scenes() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes"))
    if (e.path().extension() == ".toml") out.push_back(e.path().stem().string());
  std::sort(out.begin(), out.end());
  return out;
}

class ShippedScene : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedScene, RegimeWithEvidence) {
  const Scene scene = load_scene(std::string(TIPPE_SOURCE_DIR) + "/harness/scenes/" + GetParam() + ".toml");
  ReferenceModel m(scene);
  const BodyModel& b = m.body();
  const double e0 = energy(b, m.state());
  const int n = 200;
  std::vector<double> slip(n + 1, 0.0), e(n + 1, e0);
  double stick_time = -1, inversion_time = -1;
  for (int k = 1; k <= n && m.status() == ReferenceStatus::Ok; ++k) {
    m.advance_to(scene.run.duration * k / n);
    const ContactForces f = m.forces();
    slip[k] = m.contact_surface() == Surface::Stem ? f.slip_W[1].norm() : f.slip_W[0].norm();
    e[k] = energy(b, m.state());
  }
  for (const auto& ev : m.events()) {
    if (ev.name == "stick" && stick_time < 0) stick_time = ev.time;
    if (ev.name == "inversion" && inversion_time < 0) inversion_time = ev.time;
  }
  const bool rolls = stick_time >= 0 && m.events().back().name != "slip";
  const char* regime = inversion_time >= 0 ? "inverts" : (rolls ? "rolls" : "neither");
  std::printf("%-24s %-8s inversion %9.4f  stick %8.4f  E_end/E0 %.6f  slip at 0, 1/4, 1/2, 3/4, 1 of the run: "
              "%.3g %.3g %.3g %.3g %.3g\n",
              GetParam().c_str(), regime, inversion_time, stick_time, e.back() / e0, slip[0], slip[n / 4], slip[n / 2],
              slip[3 * n / 4], slip[n]);
  RecordProperty("regime", regime);
  EXPECT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
  // Energy never rises: every law here dissipates or conserves (1e-9 E0 for the integration).
  for (int k = 1; k <= n; ++k) EXPECT_LE(e[k], e[k - 1] + 1e-9 * std::abs(e0)) << "sample " << k;
  if (rolls && scene.contact.drilling == 0) {
    // Rolling without slip conserves energy: after the last stick the energy stays put, and
    // the top, now rolling, cannot turn over.
    const int k0 = static_cast<int>(std::ceil(stick_time / scene.run.duration * n));
    for (int k = k0 + 1; k <= n; ++k) EXPECT_NEAR(e[k], e[k0], 1e-9 * std::abs(e0));
    EXPECT_TRUE(inversion_time < 0 || inversion_time < stick_time);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ShippedScene, ::testing::ValuesIn(shipped_scenes()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace tippe
