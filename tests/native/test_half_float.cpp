// The host's binary16 -> binary32 widening (half-float readback) against
// GLM's, for every one of the 65536 bit patterns.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/packing.hpp>

#include "pipeline/half_float.h"

TEST(HalfFloat, EveryBitPatternWidensLikeGlm) {
  int mismatches = 0;
  for (uint32_t h = 0; h <= 0xffffu; ++h) {
    const float ours = mp::half_to_float(static_cast<uint16_t>(h));
    const float ref = glm::unpackHalf1x16(static_cast<glm::uint16>(h));
    const bool same = std::isnan(ref) ? std::isnan(ours) : (ours == ref && std::signbit(ours) == std::signbit(ref));
    if (!same && ++mismatches <= 5) ADD_FAILURE() << std::hex << "0x" << h << ": " << ours << " vs " << ref;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(mp::half_to_float(0x3c00u), 1.0f);
  EXPECT_EQ(mp::half_to_float(0x7bffu), 65504.0f);
  EXPECT_EQ(mp::half_to_float(0x0001u), std::ldexp(1.0f, -24));
  EXPECT_TRUE(std::isinf(mp::half_to_float(0xfc00u)) && mp::half_to_float(0xfc00u) < 0);
}
