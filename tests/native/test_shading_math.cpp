// Shading arithmetic that host and kernels share (kernels/closures/mp_shading.h),
// against the C++ library.
#include <gtest/gtest.h>

#include <cmath>

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "closures/mp_shading.h"

namespace {

// mp_atan2_upper against std::atan2 over the upper half plane, from tiny
// angles (distant or grazing area lights) to nearly pi.
TEST(ShadingMath, Atan2MatchesTheLibraryInTheUpperHalfPlane) {
  double worst = 0.0;
  for (int i = 0; i <= 20000; ++i) {
    const double a = 3.14159265358979 * i / 20000.0;
    for (const double r : {1e-6, 1e-3, 1.0, 7.5, 1e4}) {
      const float x = float(r * std::cos(a)), y = float(r * std::sin(a));
      if (y < 0.0f) continue;
      const double expected = std::atan2(double(y), double(x));
      worst = std::max(worst, std::fabs(double(mp_atan2_upper(y, x)) - expected));
    }
  }
  EXPECT_LT(worst, 4e-7);
  // Small angles keep their relative accuracy (Lambert's formula sums them).
  for (const float t : {1e-8f, 3e-6f, 2e-4f}) EXPECT_NEAR(mp_atan2_upper(t, 1.0f) / t, 1.0f, 1e-6f);
  EXPECT_EQ(mp_atan2_upper(0.0f, 1.0f), 0.0f);
  EXPECT_NEAR(mp_atan2_upper(1.0f, 0.0f), 1.5707963f, 2e-7f);
  EXPECT_NEAR(mp_atan2_upper(0.0f, -1.0f), 3.1415927f, 3e-7f);
}

}  // namespace
