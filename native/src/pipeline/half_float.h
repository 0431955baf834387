// IEEE 754 binary16 -> binary32, for Combined read back as half floats
// (RenderSettings::half_float_readback). Written as masked selects between
// the three cases so the loop vectorises: a normal half moves its exponent and
// mantissa into a float's place and rebiases the exponent (127 - 15 = 112);
// infinities and NaNs rebias once more, to the all-ones exponent; zeros and
// subnormals are their mantissa times 2^-24, converted exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace mp {

inline uint32_t half_to_float_bits(uint32_t h) {
  const uint32_t magnitude = h & 0x7fffu;
  const uint32_t normal = (magnitude << 13) + (112u << 23);
  const float small = static_cast<float>(static_cast<int32_t>(magnitude)) * 0x1p-24f;
  uint32_t small_bits;
  std::memcpy(&small_bits, &small, 4);
  // All-ones masks rather than branches, so the loop stays branch-free.
  const uint32_t is_normal = 0u - static_cast<uint32_t>(magnitude >= 0x0400u);
  const uint32_t is_special = 0u - static_cast<uint32_t>(magnitude >= 0x7c00u);
  const uint32_t wide = normal + ((112u << 23) & is_special);
  return (wide & is_normal) | (small_bits & ~is_normal) | ((h & 0x8000u) << 16);
}

inline float half_to_float(uint16_t h) {
  const uint32_t bits = half_to_float_bits(h);
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}

inline void half_to_float(const uint16_t* in, float* out, size_t count) {
  // In blocks through an integer buffer, which the compiler vectorises.
  constexpr size_t kBlock = 1024;
  uint32_t bits[kBlock];
  for (size_t start = 0; start < count; start += kBlock) {
    const size_t n = count - start < kBlock ? count - start : kBlock;
    for (size_t i = 0; i < n; ++i) bits[i] = half_to_float_bits(in[start + i]);
    std::memcpy(out + start, bits, n * 4);
  }
}

}  // namespace mp
