/* Motion blur and depth of field as a stochastic rasteriser sees them (Cook,
 * Porter & Carpenter 1984; Cook, Carpenter & Catmull 1987): every sample of
 * the camera's view carries a time t in the shutter [0, 1] and a lens
 * position.
 *
 * Motion: a grid vertex has a camera-space position at each of the
 * Scene's motion steps, evenly spread over the shutter, and moves linearly
 * between them; a sample sees every vertex at its own time.
 *
 * Lens: a sample with lens position L = (lx, ly) on the aperture (camera
 * units, the lens in the plane z = 0) sees a camera-space point P at depth
 * d = -z where the ray from L through P crosses the plane in focus, z = -F,
 * projected through the lens centre:
 *
 *   rx = ax * (P.x / d + lx * (1/F - 1/d)) + bx    (likewise y)
 *
 * a perspective projection from L, so 1/d and attributes / d stay affine in
 * raster space. The circle of confusion of depth d has raster radius
 * |ax| * R * |1/F - 1/d|. The aperture is Cycles' (kernel/camera/camera.h):
 * a disk, or a regular polygon of `blades` corners turned by the blade
 * rotation, its x scaled by 1 / the anamorphic ratio. Shared by the kernels
 * and host code. */
#ifndef MP_BLUR_H
#define MP_BLUR_H

#include "core/mp_compat.h"
#include "core/mp_hash.h"
#include "core/mp_types.h"

/* Whether samples of view f carry lens positions, times, or either. */
MP_INLINE int mp_lens_on(FrameParams f) {
  return f.lens_radius > 0.0f && !f.ortho && f.view_kind == MP_VIEW_CAMERA;
}
MP_INLINE int mp_motion_on(FrameParams f) { return f.motion_steps >= 2 && f.view_kind == MP_VIEW_CAMERA; }
MP_INLINE int mp_blur_on(FrameParams f) { return mp_lens_on(f) || mp_motion_on(f); }

/* Largest |1/F - 1/d| over depths [dmin, dmax] (dmin > 0): at an end. */
MP_INLINE float mp_defocus_max(FrameParams f, float dmin, float dmax) {
  float k = 1.0f / f.focus_distance;
  return fmax(fabs(k - 1.0f / dmin), fabs(k - 1.0f / dmax));
}

/* Raster slack, in pixels along x and y, that lens positions add to the
 * bound of points at depths [dmin, dmax] (dmin > 0). */
MP_INLINE float mp_lens_slack_x(FrameParams f, float dmin, float dmax) {
  return mp_lens_on(f) ? fabs(f.ax) * f.lens_radius * f.lens_x_scale * mp_defocus_max(f, dmin, dmax) : 0.0f;
}
MP_INLINE float mp_lens_slack_y(FrameParams f, float dmin, float dmax) {
  return mp_lens_on(f) ? fabs(f.ay) * f.lens_radius * mp_defocus_max(f, dmin, dmax) : 0.0f;
}

/* The same in the homogeneous form of the frustum's side planes
 * (a x + c d >= 0, mp_bound.h), for depths [dmin, dmax] of any sign: the
 * lens moves the plane's apex, adding at most |a| R |d/F - 1|. */
MP_INLINE float mp_lens_plane_slack(FrameParams f, float a, float radius, float dmin, float dmax) {
  if (!mp_lens_on(f)) return 0.0f;
  float k = 1.0f / f.focus_distance;
  return fabs(a) * radius * fmax(fabs(dmin * k - 1.0f), fabs(dmax * k - 1.0f));
}

/* Circle-of-confusion diameter in pixels (the larger raster axis) of a point
 * at depth d > 0. */
MP_INLINE float mp_coc_diameter(FrameParams f, float d) {
  if (!mp_lens_on(f) || !(d > 0.0f)) return 0.0f;
  float a = fmax(fabs(f.ax) * f.lens_x_scale, fabs(f.ay));
  return 2.0f * a * f.lens_radius * fabs(1.0f / f.focus_distance - 1.0f / d);
}

/* A point of the unit square as a point of the unit aperture (before the
 * anamorphic scale): Shirley & Chiu's concentric map onto the disk, or the
 * polygon as Cycles samples it (regular_polygon_sample): u picks a corner's
 * triangle (centre, corner, next corner) and the rest of u and v a point in
 * it, uniform in area. */
MP_INLINE float2 mp_aperture_point(float u, float v, int blades, float rotation) {
  const float pi = 3.14159265358979f;
  if (blades < 3) {
    float a = 2.0f * u - 1.0f, b = 2.0f * v - 1.0f;
    if (a == 0.0f && b == 0.0f) return MP_F2(0.0f, 0.0f);
    float r, phi;
    if (fabs(a) > fabs(b)) {
      r = a;
      phi = 0.25f * pi * (b / a);
    } else {
      r = b;
      phi = 0.5f * pi - 0.25f * pi * (a / b);
    }
    return MP_F2(r * cos(phi), r * sin(phi));
  }
  float n = (float)blades;
  float corner = floor(u * n);
  float w = sqrt(u * n - corner);
  float s = v * w, t = 1.0f - w;
  float wedge = pi / n;
  float px = (t + s) * cos(wedge), py = (t - s) * sin(wedge);
  float turn = rotation + corner * 2.0f * wedge;
  float c = cos(turn), sn = sin(turn);
  return MP_F2(c * px - sn * py, sn * px + c * py);
}

/* A permutation of [0, n) chosen by `seed`: an invertible hash of the bits
 * below the next power of two, walked until it lands inside (cycle walking). */
MP_INLINE uint mp_permute(uint i, uint n, uint seed) {
  uint mask = 1u;
  while (mask < n) mask <<= 1;
  mask -= 1u;
  uint x = i;
  do {
    x ^= seed & mask;
    x = (x * 0x2c1b3c6du + (seed >> 16)) & mask; /* odd multiplier: a bijection mod 2^k */
    x ^= (x >> 3) & mask;
    x = (x * 0x297a2d39u) & mask;
    x ^= (x >> 5);
  } while (x >= n);
  return x;
}

/* Time of sample slot s of the sample tile's pixel (tx, ty): slot s is time
 * stratum s of spp, jittered per pixel, so a slot's times stay within its
 * stratum (the rasteriser bounds each slot apart). */
MP_INLINE float mp_sample_time(int tx, int ty, int s, FrameParams f) {
  int spp = f.spp_x * f.spp_y;
  uint h = mp_hash_combine(mp_hash_combine(mp_hash32((uint)tx ^ (f.seed + 0x2545f491u)), (uint)ty), (uint)s);
  return ((float)s + mp_hash_unit(h)) / (float)spp;
}

/* Lens position (camera units) of sample slot s of the sample tile's pixel
 * (tx, ty): without motion, slot s is the lens stratum s of a spp_x x spp_y
 * grid over the unit square, jittered per pixel, so a slot's lens positions
 * stay within its stratum's image on the aperture; with motion the slots
 * are time strata and the lens stratum is shuffled per pixel. */
MP_INLINE float2 mp_sample_lens(int tx, int ty, int s, FrameParams f) {
  if (mp_motion_on(f))
    s = (int)mp_permute((uint)s, (uint)(f.spp_x * f.spp_y),
                        mp_hash_combine(mp_hash32((uint)ty ^ 0x7feb352du), (uint)tx) ^ f.seed);
  int sx = s % f.spp_x, sy = s / f.spp_x;
  uint h = mp_hash_combine(mp_hash_combine(mp_hash32((uint)tx ^ (f.seed + 0x51ed2701u)), (uint)ty), (uint)s);
  float u = ((float)sx + mp_hash_unit(h)) / (float)f.spp_x;
  float v = ((float)sy + mp_hash_unit(mp_hash32(h ^ 0x68bc21ebu))) / (float)f.spp_y;
  float2 a = mp_aperture_point(u, v, f.aperture_blades, f.aperture_rotation);
  return MP_F2(a.x * f.lens_radius * f.lens_x_scale, a.y * f.lens_radius);
}

/* The motion step k that time t follows and its weight w towards step
 * k + 1 (steps evenly spread over the shutter, linear between). */
MP_INLINE int mp_motion_segment(float t, int steps, float* w) {
  float x = clamp(t, 0.0f, 1.0f) * (float)(steps - 1);
  int k = min((int)x, steps - 2);
  *w = x - (float)k;
  return k;
}

/* Position at time t of a grid vertex whose positions at the motion steps
 * lie `stride` apart from p[0]. */
MP_INLINE float4 mp_motion_position(const MP_GLOBAL float4* p, ulong stride, int steps, float t) {
  float w;
  int k = mp_motion_segment(t, steps, &w);
  float4 a = p[(ulong)k * stride], b = p[(ulong)(k + 1) * stride];
  return a + w * (b - a);
}

/* Raster position of view-space point p seen from lens position L (above);
 * returns 0 where p is not in front of the lens. */
MP_INLINE int mp_project_lens(float3 p, float2 L, FrameParams f, float* rx, float* ry, float* inv_d) {
  float d = -p.z;
  if (!(d > 0.0f)) return 0;
  float inv = 1.0f / d;
  float k = 1.0f / f.focus_distance - inv;
  *rx = f.ax * (p.x * inv + L.x * k) + f.frame_bx;
  *ry = f.ay * (p.y * inv + L.y * k) + f.frame_by;
  *inv_d = inv;
  return 1;
}

#endif
