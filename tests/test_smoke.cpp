// Smoke test of the build (replaced by the real suites).
#include <gtest/gtest.h>
#include "observables.h"
TEST(Smoke, Tilt) { EXPECT_NEAR(tippe::tilt(tippe::Quat::Identity()), 0.0, 1e-15); }
