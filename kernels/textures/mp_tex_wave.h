/* Wave Texture node with Blender's conventions: bands along an axis or the
 * diagonal, rings around an axis or the origin, 20 units of phase per unit
 * of (scaled) distance, sine/saw/triangle profiles, and an fBm distortion of
 * the phase (Distortion, Detail, Detail Scale, Detail Roughness).
 * Compiles as OpenCL C 1.2 and C++17 through mp_compat.h. */
#ifndef MP_TEX_WAVE_H
#define MP_TEX_WAVE_H

#include "core/mp_compat.h"
#include "textures/mp_tex_noise.h"

#define MP_WAVE_BANDS 0
#define MP_WAVE_RINGS 1
#define MP_WAVE_PROFILE_SIN 0
#define MP_WAVE_PROFILE_SAW 1
#define MP_WAVE_PROFILE_TRI 2

#define MP_TX_PI_2 1.57079632679489661923f
#define MP_TX_2PI 6.28318530717958647692f

/* wave_type 0 bands, 1 rings. direction: bands 0 X, 1 Y, 2 Z, 3 diagonal;
 * rings 0 X, 1 Y, 2 Z, 3 spherical. profile 0 sine, 1 saw, 2 triangle.
 * Inputs as the node's sockets receive them; fac in [0, 1], color = fac. */
MP_INLINE void mp_tex_wave(float3 p, int wave_type, int direction, int profile, float scale, float distortion,
                           float detail, float detail_scale, float detail_roughness, float phase, int blender_version,
                           float* fac, float3* color) {
  /* Scaled point, nudged off exact lattice values as Blender does. */
  float x = (p.x * scale + 0.000001f) * 0.999999f;
  float y = (p.y * scale + 0.000001f) * 0.999999f;
  float z = (p.z * scale + 0.000001f) * 0.999999f;

  float n;
  if (wave_type == MP_WAVE_BANDS) {
    if (direction == 0) n = x * 20.0f;
    else if (direction == 1) n = y * 20.0f;
    else if (direction == 2) n = z * 20.0f;
    else n = (x + y + z) * 10.0f;
  }
  else {
    float rx = direction == 0 ? 0.0f : x;
    float ry = direction == 1 ? 0.0f : y;
    float rz = direction == 2 ? 0.0f : z;
    n = sqrt(rx * rx + ry * ry + rz * rz) * 20.0f;
  }

  n += phase;

  if (distortion != 0.0f) {
    float q[3];
    q[0] = x * detail_scale;
    q[1] = y * detail_scale;
    q[2] = z * detail_scale;
    float f = blender_version < 400 ? mp_tx_fractal_noise_legacy(q, 3, detail, detail_roughness, blender_version)
                                    : mp_tx_noise_fbm(q, 3, detail, detail_roughness, 2.0f, 1, blender_version);
    n += distortion * (f * 2.0f - 1.0f);
  }

  float v;
  if (profile == MP_WAVE_PROFILE_SIN) {
    v = 0.5f + 0.5f * sin(n - MP_TX_PI_2);
  }
  else if (profile == MP_WAVE_PROFILE_SAW) {
    n /= MP_TX_2PI;
    v = n - floor(n);
  }
  else {
    n /= MP_TX_2PI;
    v = fabs(n - floor(n + 0.5f)) * 2.0f;
  }
  *fac = v;
  *color = MP_F3(v, v, v);
}

#endif
