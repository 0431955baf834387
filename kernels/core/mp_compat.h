/* Lets the device math headers compile both as OpenCL C 1.2 and as C++17.
 * The kernels and the host tests include the same headers (patch evaluation,
 * bounds, raster math), so the CPU reference and the device agree by
 * construction. Only the vocabulary below differs between the two languages. */
#ifndef MP_COMPAT_H
#define MP_COMPAT_H

#ifdef __OPENCL_VERSION__
#define MP_INLINE inline
#define MP_GLOBAL __global
#define MP_CONSTANT __constant
#define MP_F2(x, y) ((float2)((x), (y)))
#define MP_F3(x, y, z) ((float3)((x), (y), (z)))
#define MP_F4(x, y, z, w) ((float4)((x), (y), (z), (w)))
#define MP_XYZ(v) ((v).xyz)
/* x^y for x > 0, or x = 0 with y > 0 (shading exponents): in single
 * precision, where PoCL's pow and powr go through double-precision log and
 * exp (a fifth of a diffuse-and-plastic frame's time on the CPU). */
#define MP_POWR(x, y) exp2((y) * log2(x))
#define MP_FMOD(x, y) fmod((x), (y))
#else
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <algorithm>
#include <cstring>
typedef glm::vec3 float3;
typedef glm::vec4 float4;
typedef glm::vec2 float2;
typedef std::uint32_t uint;
typedef std::uint64_t ulong;
typedef std::uint16_t ushort;
typedef std::uint8_t uchar;
#define MP_INLINE inline
#define MP_GLOBAL
#define MP_CONSTANT inline constexpr
#define MP_F2(x, y) (glm::vec2((x), (y)))
#define MP_F3(x, y, z) (glm::vec3((x), (y), (z)))
#define MP_F4(x, y, z, w) (glm::vec4((x), (y), (z), (w)))
#define MP_XYZ(v) (glm::vec3(v))
#define MP_POWR(x, y) (std::pow((x), (y)))
#define MP_FMOD(x, y) (std::fmod((x), (y)))
namespace mp_compat {
inline float dot(glm::vec3 a, glm::vec3 b) { return glm::dot(a, b); }
inline glm::vec3 cross(glm::vec3 a, glm::vec3 b) { return glm::cross(a, b); }
inline float length(glm::vec3 a) { return glm::length(a); }
inline glm::vec3 normalize(glm::vec3 a) { return glm::normalize(a); }
inline glm::vec3 fmin(glm::vec3 a, glm::vec3 b) { return glm::min(a, b); }
inline glm::vec3 fmax(glm::vec3 a, glm::vec3 b) { return glm::max(a, b); }
inline glm::vec3 fabs(glm::vec3 a) { return glm::abs(a); }
inline float fmin(float a, float b) { return std::fmin(a, b); }
inline float fmax(float a, float b) { return std::fmax(a, b); }
inline float clamp(float x, float a, float b) { return std::min(std::max(x, a), b); }
inline int clamp(int x, int a, int b) { return std::min(std::max(x, a), b); }
inline uint max(uint a, uint b) { return std::max(a, b); }
inline uint min(uint a, uint b) { return std::min(a, b); }
inline float mix(float a, float b, float t) { return a + (b - a) * t; }
inline glm::vec3 mix(glm::vec3 a, glm::vec3 b, float t) { return a + (b - a) * t; }
inline uint as_uint(float f) { uint u; std::memcpy(&u, &f, 4); return u; }
inline float as_float(uint u) { float f; std::memcpy(&f, &u, 4); return f; }
inline int max(int a, int b) { return std::max(a, b); }
inline int min(int a, int b) { return std::min(a, b); }
// OpenCL's float overloads (the C library's take and return double).
inline float pow(float x, float y) { return std::pow(x, y); }
inline float cos(float x) { return std::cos(x); }
inline float sin(float x) { return std::sin(x); }
inline float acos(float x) { return std::acos(x); }
inline float atan2(float y, float x) { return std::atan2(y, x); }
inline float exp(float x) { return std::exp(x); }
}  // namespace mp_compat
#include <cstring>
using namespace mp_compat;
using std::ceil;
using std::floor;
using std::sqrt;
using std::fabs;
using std::log2;
using std::isfinite;
#endif

#endif
