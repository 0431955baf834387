/* What shading needs of lights and normals: the world's irradiance, area
 * and sized lights' irradiance, spot cones, and the corrections Cycles
 * makes to normals set through a BSDF's input. Surfaces are lit as
 * closures (mp_shade_closures.h).
 * Everything is in camera space. */
#ifndef MP_SHADING_H
#define MP_SHADING_H

#include "geometry/mp_instance.h"

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "shadow/mp_shadow.h"
#include "closures/mp_world.h"

#define MP_PI 3.14159265358979f
#define MP_AREA_MAX_VERTICES 18  /* a 16-gon plus one vertex from horizon clipping, plus slack */
#define MP_ELLIPSE_SIDES 16

MP_INLINE float mp_smoothstep(float e0, float e1, float x) {
  if (e1 <= e0) return x >= e1 ? 1.0f : 0.0f;
  float t = clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

MP_INLINE float3 mp_light_f3(const MP_GLOBAL float* v) { return MP_F3(v[0], v[1], v[2]); }

/* The world's irradiance over pi (a radiance, as an ambient light's) on a
 * surface with camera-space normal n, from an MP_LIGHT_ENVIRONMENT light:
 * E(n) / pi = sum of c_lm Y_lm(R n) (mp_world.h), with R camera -> world
 * and the coefficients already scaled by the cosine lobe's A_l / pi. The
 * two records hold 40 floats past their colour fields:
 * R's rows, then the coefficients (world_lighting.cpp writes them). */
MP_INLINE float mp_env_float(MP_GLOBAL const DeviceLight* lt, int i) {
  MP_GLOBAL const float* f = (MP_GLOBAL const float*)lt;
  return i < 20 ? f[4 + i] : f[28 + (i - 20)];
}
/* A camera-space direction in world space (R's rows). */
MP_INLINE float3 mp_env_to_world(MP_GLOBAL const DeviceLight* lt, float3 n) {
  return MP_F3(mp_env_float(lt, 0) * n.x + mp_env_float(lt, 1) * n.y + mp_env_float(lt, 2) * n.z,
               mp_env_float(lt, 3) * n.x + mp_env_float(lt, 4) * n.y + mp_env_float(lt, 5) * n.z,
               mp_env_float(lt, 6) * n.x + mp_env_float(lt, 7) * n.y + mp_env_float(lt, 8) * n.z);
}
MP_INLINE float3 mp_env_irradiance(MP_GLOBAL const DeviceLight* lt, float3 n) {
  float basis[9];
  mp_sh9_basis(mp_env_to_world(lt, n), basis);
  float3 e = MP_F3(0.0f, 0.0f, 0.0f);
  for (int k = 0; k < 9; ++k)
    e += basis[k] * MP_F3(mp_env_float(lt, 9 + 3 * k), mp_env_float(lt, 10 + 3 * k), mp_env_float(lt, 11 + 3 * k));
  return MP_F3(fmax(e.x, 0.0f), fmax(e.y, 0.0f), fmax(e.z, 0.0f));
}

/* atan2(y, x) for y >= 0, to within 2e-7 radians: octant reduction to
 * [0, 1], then to |t| <= tan(pi/8), and the minimax polynomial of Cephes'
 * atanf (Moshier). PoCL's atan2 is a general software routine that cost
 * the area lights' shading several times their other arithmetic. */
MP_INLINE float mp_atan2_upper(float y, float x) {
  float ax = fabs(x), hi = fmax(ax, y), lo = fmin(ax, y);
  float t = hi > 0.0f ? lo / hi : 0.0f, base = 0.0f;
  if (t > 0.41421356f) {
    t = (t - 1.0f) / (t + 1.0f);
    base = 0.78539816f;
  }
  float z = t * t;
  float r = base + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z -
                     3.33329491539e-1f) * z * t + t);
  if (y > ax) r = 1.57079633f - r;
  return x < 0.0f ? 3.14159265f - r : r;
}

/* Irradiance factor of a uniformly emitting polygon seen from a point with
 * normal n (vertices relative to the point): the polygon's projected solid
 * angle, by Lambert's formula, after clipping the polygon to the hemisphere
 * above the surface. Multiplied by the emitted radiance it is the irradiance. */
MP_INLINE float mp_polygon_irradiance(float3 n, float3* v, int count) {
  float3 clipped[MP_AREA_MAX_VERTICES];
  int m = 0;
  for (int i = 0; i < count; ++i) {
    float3 a = v[i], b = v[(i + 1) % count];
    float da = dot(n, a), db = dot(n, b);
    if (da >= 0.0f && m < MP_AREA_MAX_VERTICES) clipped[m++] = a;
    if ((da >= 0.0f) != (db >= 0.0f) && m < MP_AREA_MAX_VERTICES) clipped[m++] = a + (b - a) * (da / (da - db));
  }
  if (m < 3) return 0.0f;
  float sum = 0.0f;
  for (int i = 0; i < m; ++i) {
    float la = length(clipped[i]), lb = length(clipped[(i + 1) % m]);
    if (!(la > 0.0f) || !(lb > 0.0f)) continue;
    float3 ua = clipped[i] / la, ub = clipped[(i + 1) % m] / lb;
    float3 c = cross(ua, ub);
    float lc = length(c);
    if (!(lc > 1e-12f)) continue;
    /* atan2 keeps the small angles of distant or grazing lights accurate,
     * where acos(dot) loses most of its digits. */
    float angle = mp_atan2_upper(lc, dot(ua, ub));
    sum += angle * dot(n, c / lc);
  }
  return 0.5f * fabs(sum);
}

/* Irradiance at p (normal n) from an area light, and the direction to its centre. */
MP_INLINE float mp_area_irradiance(MP_GLOBAL const DeviceLight* lt, float3 p, float3 n, float3* to_centre) {
  float3 c = mp_light_f3(lt->position), dir = mp_light_f3(lt->direction);
  float3 u = mp_light_f3(lt->axis_u), w = mp_light_f3(lt->axis_v);
  *to_centre = normalize(c - p);
  if (dot(p - c, dir) <= 0.0f) return 0.0f; /* behind the emitting side */
  float3 verts[MP_AREA_MAX_VERTICES];
  int count;
  if (lt->axis_u[3] == (float)MP_AREA_ELLIPSE) {
    /* A 16-gon with the ellipse's area. */
    float k = sqrt(MP_PI / (0.5f * (float)MP_ELLIPSE_SIDES * sin(2.0f * MP_PI / (float)MP_ELLIPSE_SIDES)));
    for (int i = 0; i < MP_ELLIPSE_SIDES; ++i) {
      float a = 2.0f * MP_PI * (float)i / (float)MP_ELLIPSE_SIDES;
      verts[i] = c + k * ((float)cos(a) * u + (float)sin(a) * w) - p;
    }
    count = MP_ELLIPSE_SIDES;
  } else {
    verts[0] = c - u - w - p;
    verts[1] = c + u - w - p;
    verts[2] = c + u + w - p;
    verts[3] = c - u + w - p;
    count = 4;
  }
  return mp_polygon_irradiance(n, verts, count);
}

/* Irradiance factor (projected solid angle over the emitting area) of a
 * point or spot light with a radius r (DeviceLight.cone[3]) at p with
 * normal n: the radiance of its intensity spread over a disk of radius r,
 * the light as Cycles samples it (docs/blender-conventions.md): a disk at
 * the light facing p, or (direction[3] = 1, Blender 4.1's point light
 * without soft falloff) a sphere, whose silhouette is the smaller disk
 * r sqrt(1 - r^2/d^2) at d - r^2/d. Far from the light it is the point
 * light's cos / d^2 times d^2 / (d^2 + r^2) (the disk) or 1 (the sphere). */
MP_INLINE float mp_sized_light_factor(MP_GLOBAL const DeviceLight* lt, float3 to_light, float d2, float3 n) {
  float r = lt->cone[3], d = sqrt(d2);
  int sphere = lt->direction[3] > 0.5f;
  float3 l = to_light / d;
  if (r < 0.05f * d) {
    float c = fmax(dot(n, l), 0.0f);
    return sphere ? c / d2 : c / (d2 + r * r);
  }
  if (sphere && d <= r) return fmax(dot(n, l), 0.0f) / (r * r); /* inside: half its radiance's pi */
  float rr = sphere ? r * sqrt(1.0f - r * r / d2) : r;
  float3 c = sphere ? to_light * (1.0f - r * r / d2) : to_light;
  float3 a = fabs(l.x) < 0.9f ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f);
  float3 u = normalize(cross(l, a)), w = cross(l, u);
  float k = rr * sqrt(MP_PI / (0.5f * (float)MP_ELLIPSE_SIDES * sin(2.0f * MP_PI / (float)MP_ELLIPSE_SIDES)));
  float3 verts[MP_AREA_MAX_VERTICES];
  for (int i = 0; i < MP_ELLIPSE_SIDES; ++i) {
    float t = 2.0f * MP_PI * (float)i / (float)MP_ELLIPSE_SIDES;
    verts[i] = c + k * ((float)cos(t) * u + (float)sin(t) * w);
  }
  return mp_polygon_irradiance(n, verts, MP_ELLIPSE_SIDES) / (MP_PI * r * r);
}

/* A spot light's cone at p: cos(angle to the axis)^beam times the smooth
 * step between the cone's inner and outer angles. A spot with a radius is
 * a disk of lights facing p, each evaluating the cone from its own
 * position, as Cycles does per light sample: the mask averages over the
 * disk, which blurs the cone's edge by its angular size. */
MP_INLINE float mp_spot_mask(MP_GLOBAL const DeviceLight* lt, float3 p) {
  float3 c = mp_light_f3(lt->position), axis = mp_light_f3(lt->direction);
  float r = lt->cone[3];
  int taps = r > 0.0f ? 8 : 1;
  float3 w = normalize(p - c);
  float3 a = fabs(w.x) < 0.9f ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f);
  float3 u = normalize(cross(w, a)), v = cross(w, u);
  float sum = 0.0f;
  float2 turn = MP_F2(1.0f, 0.0f);
  for (int k = 0; k < taps; ++k, turn = mp_golden_step(turn)) {
    float2 d = taps > 1 ? sqrt(((float)k + 0.5f) / (float)taps) * turn : MP_F2(0.0f, 0.0f);
    float cosangle = dot(normalize(p - (c + r * (d.x * u + d.y * v))), axis);
    float m = cosangle > 0.0f ? MP_POWR(cosangle, lt->cone[2]) : 0.0f;
    sum += m * mp_smoothstep(lt->cone[0], lt->cone[1], cosangle);
  }
  return sum / (float)taps;
}

/* What shading needs to shadow a vertex: the maps (mp_shadow.h), the
 * receiver's geometric normal (its tangent plane) and pixel footprint, and
 * whether it is a ribbon's (mp_ribbon.h): a strip facing the camera that
 * stands for a round fibre, whose tangent plane says nothing of the fibre
 * as the lights see it. */
typedef struct {
  const MpShadowMaps* maps;
  float3 normal;
  float footprint;
  int ribbon;
} MpShadowQuery;

/* A shading normal n (unit, on the viewer's side of the geometric normal
 * ng; v the unit direction to the viewer) turned towards ng just enough
 * that the mirror direction of v about it stays above the surface by
 * min(0.9 (ng . v), 0.01), the condition Cycles imposes on the normals
 * linked into its BSDFs. With X the unit tangent part of n, a normal at
 * angle a from ng reflects v to a height vx sin 2a + vz cos 2a, so the
 * bound is reached at 2a = phi +- acos(t / rho); the admissible solution
 * nearest n is taken. */
MP_INLINE float3 mp_valid_reflection_normal(float3 ng, float3 v, float3 n) {
  float vz = dot(ng, v);
  float t = fmin(0.9f * vz, 0.01f);
  float3 r = 2.0f * dot(n, v) * n - v;
  if (dot(ng, r) >= t) return n;
  float3 x = n - dot(n, ng) * ng;
  float xl = length(x);
  if (!(xl > 1e-7f)) return ng;
  x = x / xl;
  float vx = dot(v, x);
  float rho = sqrt(vx * vx + vz * vz);
  if (!(rho > 0.0f)) return ng;
  float phi = atan2(vx, vz), spread = acos(fmin(fmax(t / rho, -1.0f), 1.0f));
  float a0 = atan2(dot(n, x), dot(n, ng));
  float best = 0.0f, best_gap = 1e30f;
  for (int k = 0; k < 2; ++k) {
    float a = 0.5f * (phi + (k == 0 ? spread : -spread));
    if (a < 0.0f || a > 1.5707964f) continue;
    float gap = fabs(a - a0);
    if (gap < best_gap) best = a, best_gap = gap;
  }
  return sin(best) * x + cos(best) * ng;
}

/* Shadowing of a bumped diffuse surface by the unbumped one it stands for
 * (Chiang, Li, Burley, "Taming the Shadow Terminator", SIGGRAPH 2019 talk),
 * as Cycles applies it to diffuse closures whose normal differs from the
 * surface's: with g = (ng . l) / ((n . l)(ng . n)), full light for g >= 1,
 * none for g < 0, else the smooth step -g^3 + g^2 + g. */
MP_INLINE float mp_bump_shadowing(float3 ng, float3 n, float3 l) {
  float denom = dot(n, l) * dot(ng, n);
  float g = denom != 0.0f ? dot(ng, l) / denom : 0.0f;
  if (g >= 1.0f) return 1.0f;
  if (g < 0.0f) return 0.0f;
  return -g * g * g + g * g + g;
}

/* Blender 4.0's version (Cycles' bump_shadowing_term since 4.0, after Conty
 * Estevez, Lecocq and Stein, "A Microfacet-Based Shadowing Function to Solve
 * the Bump Terminator Problem", 2019): no light from the wrong side of the
 * smooth surface ns for the bumped normal n; with the material's Bump Map
 * Correction, the Smith GGX shadowing G1 at the light's angle to ns, with
 * alpha^2 = min(tan^2(angle between n and ns) / 8, 1). */
MP_INLINE float mp_bump_shadowing_v4(float3 ns, float3 n, float3 l, int correction) {
  float cos_nsl = dot(ns, l), cos_nsn = dot(ns, n), cos_nl = dot(n, l);
  if (cos_nsl * cos_nsn * cos_nl < 0.0f) return 0.0f;
  if (!correction) return 1.0f;
  float cos_i = fabs(cos_nsl), cos_d = fabs(cos_nsn);
  if (cos_d >= 1.0f || cos_i >= 1.0f) return 1.0f;
  if (cos_i < 1e-6f) return 0.0f;
  float alpha2 = fmin(fmax(0.125f * (1.0f / (cos_d * cos_d) - 1.0f), 0.0f), 1.0f);
  float tan2_i = 1.0f / (cos_i * cos_i) - 1.0f;
  float lambda = 0.5f * (sqrt(1.0f + alpha2 * tan2_i) - 1.0f);
  return 1.0f / (1.0f + lambda);
}

/* The smooth shading normal of a patch at (u, v) (mp_patch.h,
 * MP_PATCH_NORMALS), made to face the viewer as the surface normal `ng`
 * does, as Cycles flips a smooth normal with the geometric one on back
 * faces; zero when the patch has none. */
MP_INLINE float3 mp_face_shading_normal(const MP_GLOBAL float4* normals, uint patch, float u, float v, float3 ng,
                                        float3 p, int ortho, const MpPlacement* place) {
  const MP_GLOBAL float4* c = normals + (ulong)patch * MP_PATCH_NORMALS;
  float3 n = mp_place_normal(place, (1.0f - u) * (1.0f - v) * MP_XYZ(c[0]) + u * (1.0f - v) * MP_XYZ(c[1]) +
                                        u * v * MP_XYZ(c[2]) + (1.0f - u) * v * MP_XYZ(c[3]));
  float len = length(n);
  if (!(len > 0.0f) || !isfinite(len)) return MP_F3(0.0f, 0.0f, 0.0f);
  n = n / len;
  if (dot(n, ng) < 0.0f) n = -n;
  float3 view = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : -p;
  return dot(ng, view) < 0.0f ? -n : n;
}

#endif
