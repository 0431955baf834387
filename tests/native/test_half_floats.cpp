// Half floats widened to floats (native/src/io/half_floats.h): every one of
// the 65,536 halves, the portable conversion against the processor's own
// (F16C, where this machine has it) bit for bit, and against values known
// from IEEE 754's definition of binary16.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "io/half_floats.h"

namespace mp::test {
namespace {

uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

TEST(HalfFloats, KnownValues) {
  EXPECT_EQ(half_to_float(0x3c00), 1.0f);
  EXPECT_EQ(half_to_float(0xc000), -2.0f);
  EXPECT_EQ(half_to_float(0x7bff), 65504.0f);                      // the largest half
  EXPECT_EQ(half_to_float(0x0400), std::ldexp(1.0f, -14));         // the smallest normal
  EXPECT_EQ(half_to_float(0x0001), std::ldexp(1.0f, -24));         // the smallest subnormal
  EXPECT_EQ(half_to_float(0x03ff), std::ldexp(1023.0f, -24));      // the largest subnormal
  EXPECT_EQ(half_to_float(0x3555), std::ldexp(1365.0f, -12));      // 0.333251953125
  EXPECT_EQ(bits(half_to_float(0x7c01)), 0x7fc02000u);             // a signalling NaN, made quiet
  EXPECT_EQ(bits(half_to_float(0x8000)), 0x80000000u);             // negative zero
  EXPECT_EQ(half_to_float(0x7c00), std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(half_to_float(0x7e00)));
}

TEST(HalfFloats, EveryHalfAsTheProcessorWidensIt) {
  std::vector<uint16_t> all(65536);
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<uint16_t>(i);
  std::vector<float> wide(all.size());
  halves_to_floats(all.data(), wide.data(), all.size());
  size_t differ = 0;
  for (size_t i = 0; i < all.size(); ++i) differ += bits(wide[i]) != bits(half_to_float(all[i]));
  EXPECT_EQ(differ, 0u);
  // Where F16C did the batch, the portable code matched the hardware; say so.
  if (!halves_use_f16c()) GTEST_SKIP() << "no F16C here: both sides were the portable conversion";
}

}  // namespace
}  // namespace mp::test
