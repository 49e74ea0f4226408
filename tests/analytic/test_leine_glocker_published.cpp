// Leine and Glocker's top against what others computed of it: an independent implementation of their model by their own group, and the time read off their figure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "analytic/reference_model.h"
#include "harness/io/scene_io.h"
#include "analytic/observables.h"
#include "tests/support/fixtures.h"
#include "tests/support/reference_runs.h"

namespace tippe::test_leine_glocker_published {
namespace {

using fixtures::first_event;

double stem_touchdown(Scene s) {
  s.run.duration = 1.45;  // the touchdown is at ~1.37 s
  ReferenceModel m(s);
  m.advance_to(s.run.duration);
  EXPECT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
  return first_event(m.events(), "stem_contact").value_or(-1.0);
}

// The same top, law and start solved by code nobody here wrote: the tippe-top benchmark of the
// public repository JonasBreuling/PyNonsmooth (commit 93c16cd; "Tippetop_Leine2003", the model
// of Leine and Glocker 2003, Chapter 5, as coded for Capobianco, Harsch, Eugster and Leine 2021,
// IJNME, Section 10.6), by Moreau's time-stepping with fixed-point tolerance 1e-12 on the
// impulses (scripts/independent-leine-glocker.py reruns it). Its drilling bound is
// mu (3 pi / 16) a, a Hertzian patch of radius a = 0.5 mm: mu_d = 8.8357e-5 m, where the scene's
// uniform patch gives 2/3 mu a = 1e-4 m. First stem contact (its first step with a closed stem
// gap), by step size:
//   step       1e-4      3e-5      1e-5      3e-6
//   Hertzian   1.37160   1.37259   1.37199   1.371489
//   uniform    -         -         1.37458   1.374234
// The reference: 1.371043 (Hertzian) and 1.373318 (uniform), 0.45 and 0.92 ms before the finest
// steps. The bound, 2 ms, is twice the independent result's own spread over its steps (1.1 ms,
// first order and not monotone); the published reading (~1.5 s) is 130 ms away, and mu_d off by
// 25 % moves the touchdown by 5 ms (0.75e-4 m: 1.36837 s).
TEST(LeineGlockerPublished, StemTouchdownAgreesWithAnIndependentImplementation) {
  Scene uniform = fixtures::shipped_reference_scene("leine_glocker_coupled");
  ASSERT_DOUBLE_EQ(uniform.contact.drilling, 1e-4);  // the values above are for this scene
  Scene hertzian = uniform;
  hertzian.contact.drilling = 0.3 * 3.0 * M_PI / 16.0 * 0.5e-3;
  const double t_uniform = stem_touchdown(uniform), t_hertzian = stem_touchdown(hertzian);
  std::printf("stem touchdown: uniform patch %.6f s (independent 1.374234), Hertzian %.6f s (independent 1.371489)\n",
              t_uniform, t_hertzian);
  EXPECT_NEAR(t_uniform, 1.374234, 2e-3);
  EXPECT_NEAR(t_hertzian, 1.371489, 2e-3);
}

// What "about 1.5 s" on Leine and Glocker's figure is. Their top first touches its stem at
// 1.37 s in the reference and in the independent implementation above alike; the top then rises
// on its stem and stands most nearly upright (the largest tilt of the scene's 3 s, 3.13 rad) at
// 1.489 s (the independent implementation, step 1e-5: 3.127 rad at 1.4927 s). The figure's
// ~1.5 s is that moment, read to two digits (+-0.05 s); the first contact
// is 0.127 s earlier, which is why reading the figure's time as the touchdown looked like a
// disagreement (withdrawn, docs/findings/leine-glocker-coupled.md).
TEST(LeineGlockerPublished, StandsOnItsStemAtThePublishedTime) {
  const Scene s = fixtures::shipped_reference_scene("leine_glocker_coupled");
  ReferenceModel m(s);
  const double dt = 1e-3;  // the scene's sample interval: the time of the largest tilt to 1 ms
  double t_max = -1.0, th_max = 0.0;
  for (int k = 1; k * dt <= s.run.duration + 1e-12; ++k) {
    m.advance_to(k * dt);
    ASSERT_EQ(m.status(), ReferenceStatus::Ok) << m.status_detail();
    const double th = tilt(m.state().q_WB);
    if (th > th_max) t_max = k * dt, th_max = th;
  }
  const double t_touch = first_event(m.events(), "stem_contact").value_or(-1.0);
  std::printf("leine_glocker_coupled: stem touchdown at %.6f s, most upright on the stem at %.3f s (tilt %.4f rad)\n",
              t_touch, t_max, th_max);
  ASSERT_GT(t_touch, 0.0);
  EXPECT_GT(t_max, t_touch);
  EXPECT_NEAR(t_max, 1.5, 0.05);
  EXPECT_GT(th_max, 3.0);  // upright on the stem: within 0.15 rad of pi
}

}  // namespace
}  // namespace tippe
