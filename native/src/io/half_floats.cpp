#include "io/half_floats.h"

#include <cstring>

#if defined(__x86_64__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace mp {

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t(h & 0x8000u) << 16;
  uint32_t exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu, bits;
  if (exponent == 0x1f) {
    // Infinity, or NaN with its payload, made quiet as IEEE 754's
    // conversions (and F16C) make a signalling NaN.
    bits = sign | 0x7f800000u | (mantissa << 13) | (mantissa ? 0x00400000u : 0u);
  } else if (exponent != 0) {
    bits = sign | ((exponent + 112) << 23) | (mantissa << 13);  // rebias 15 -> 127
  } else if (mantissa == 0) {
    bits = sign;
  } else {  // subnormal: normalise the mantissa
    exponent = 113;
    while (!(mantissa & 0x400u)) mantissa <<= 1, --exponent;
    bits = sign | (exponent << 23) | ((mantissa & 0x3ffu) << 13);
  }
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

namespace {

void halves_to_floats_portable(const uint16_t* in, float* out, size_t n) {
  for (size_t i = 0; i < n; ++i) out[i] = half_to_float(in[i]);
}

#if defined(__x86_64__)
// Eight at a time with VCVTPH2PS.
__attribute__((target("avx,f16c"))) void halves_to_floats_f16c(const uint16_t* in, float* out, size_t n) {
  size_t i = 0;
  for (; i + 8 <= n; i += 8)
    _mm256_storeu_ps(out + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i))));
  halves_to_floats_portable(in + i, out + i, n - i);
}

// F16C, and a system that keeps AVX registers (which its encoding needs):
// CPUID leaf 1, ECX bit 29 (not every compiler's __builtin_cpu_supports
// knows the name).
bool has_f16c() {
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __builtin_cpu_supports("avx") && __get_cpuid(1, &a, &b, &c, &d) && (c & bit_F16C);
}
#endif

}  // namespace

bool halves_use_f16c() {
#if defined(__x86_64__)
  static const bool f16c = has_f16c();
  return f16c;
#else
  return false;
#endif
}

void halves_to_floats(const uint16_t* in, float* out, size_t n) {
#if defined(__x86_64__)
  if (halves_use_f16c()) return halves_to_floats_f16c(in, out, n);
#endif
  halves_to_floats_portable(in, out, n);
}

}  // namespace mp
