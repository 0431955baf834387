/* Subsurface scattering as a Lambertian lobe whose albedo is what Cycles'
 * random walk returns.
 *
 * From Blender 4.0 on a walk starts by refracting the camera ray through a
 * GGX boundary of the closure's IOR and roughness (Random Walk (Skin) does
 * so for half of its walks, with roughness 1, and enters diffusely for the
 * other half) and leaves through a Lambertian exit. Light therefore comes
 * back in proportion to the lamp's cosine, as from a Lambertian surface,
 * but not as the Color: walks that start steeply go deep and are absorbed
 * more, grazing ones leave early. The ratio returned / Color, for a thick
 * flat slab, was measured from Cycles 4.5 for each albedo, view cosine,
 * entry roughness and IOR (scripts/tables/subsurface_albedo_cycles.py,
 * mp_subsurface_table.h) and is read here multilinearly, per channel.
 * Left out: light crossing the surface sideways (spread by the radius over
 * curvature and thin parts). Blender 3.x's walk enters diffusely and
 * returns the Color at every angle, as does Christensen-Burley: those stay
 * Lambert. Compiles as OpenCL C and C++. */
#ifndef MP_SUBSURFACE_H
#define MP_SUBSURFACE_H

#include "core/mp_compat.h"
#include "closures/mp_closures.h"
#include "tables/mp_subsurface_table.h"

/* Cycles' smallest radius for a walk: a channel below it is Lambert. */
#define MP_SSS_MIN_RADIUS 1e-8f

/* x's place on the albedo axis (0 .. MP_SSS_ALBEDOS - 1). */
MP_INLINE float mp_sss_albedo_place(float x) {
  int last = MP_SSS_ALBEDOS - 1;
  x = !(x > 0.0f) ? 0.0f : x; /* NaN: 0 */
  x = clamp(x, mp_sss_albedo_axis[0], mp_sss_albedo_axis[last]);
  int i = 0;
  while (i < last - 1 && x > mp_sss_albedo_axis[i + 1]) ++i;
  return (float)i + (x - mp_sss_albedo_axis[i]) / (mp_sss_albedo_axis[i + 1] - mp_sss_albedo_axis[i]);
}

/* Row `row` of the walk's or the skin's table at albedo place x. */
MP_INLINE float mp_sss_row(int skin, int row, float x) {
  int i = (int)fmin(floor(x), (float)(MP_SSS_ALBEDOS - 2)), k = row * MP_SSS_ALBEDOS + i;
  float t = x - (float)i;
  return skin ? (1.0f - t) * mp_sss_skin[k] + t * mp_sss_skin[k + 1]
              : (1.0f - t) * mp_sss_walk[k] + t * mp_sss_walk[k + 1];
}

/* A uniform axis of n points: the place of x in [0, n - 1] and its cell. */
MP_INLINE int mp_sss_cell(float x, int n, float* t) {
  x = clamp(x, 0.0f, (float)(n - 1));
  int i = (int)fmin(floor(x), (float)(n - 2));
  *t = x - (float)i;
  return i;
}

/* The ratio returned / Color of one channel of albedo a: the view cosine's,
 * roughness's and IOR's cells (start, weights) are shared by the channels. */
MP_INLINE float mp_sss_channel(float a, int model, int eta_i, float eta_t, int alpha_i, float alpha_t, int cos_i,
                               float cos_t) {
  float x = mp_sss_albedo_place(a), r = 0.0f;
  for (int e = 0; e < 2; ++e) {
    float we = e ? eta_t : 1.0f - eta_t;
    if (!(we > 0.0f)) continue;
    int alphas = model == MP_SSS_SKIN ? 1 : 2;
    for (int k = 0; k < alphas; ++k) {
      float wa = model == MP_SSS_SKIN ? 1.0f : k ? alpha_t : 1.0f - alpha_t;
      if (!(wa > 0.0f)) continue;
      for (int c = 0; c < 2; ++c) {
        float wc = c ? cos_t : 1.0f - cos_t;
        if (!(wc > 0.0f)) continue;
        int row = model == MP_SSS_SKIN
                      ? (eta_i + e) * MP_SSS_COSINES + cos_i + c
                      : ((eta_i + e) * MP_SSS_ROUGHNESS + alpha_i + k) * MP_SSS_COSINES + cos_i + c;
        r += we * wa * wc * mp_sss_row(model == MP_SSS_SKIN, row, x);
      }
    }
  }
  return r;
}

/* What a walk returns per unit Color, per channel: albedo the closure's
 * Color (at most 1), nv the view's cosine to its normal, alpha the entry's
 * GGX roughness, ior its IOR (as given: Cycles clamps it to [1.01, 3.8],
 * which the table's ends hold), radius per channel in scene units. */
MP_INLINE float3 mp_subsurface_ratio(int model, float3 albedo, float3 radius, float nv, float alpha, float ior) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f);
  if (model != MP_SSS_WALK && model != MP_SSS_SKIN) return one;
  /* The view cosine's axis: 0.05, then 1/8 .. 1 in eighths. */
  float c = nv > 0.0f ? fmin(nv, 1.0f) : 0.0f; /* NaN: 0 */
  float cos_place = c < 0.125f ? (c - 0.05f) / 0.075f : 8.0f * c;
  /* The IOR's axis: 1 / IOR from 0.25 to 1 in 4 steps; the roughness's
   * from 0 to 1 in 4. */
  float eta = 1.0f / fmax(ior, 1e-5f);
  float eta_t, alpha_t, cos_t;
  int eta_i = mp_sss_cell((eta - 0.25f) / 0.1875f, MP_SSS_ETAS, &eta_t);
  int alpha_i = mp_sss_cell(alpha > 0.0f ? 4.0f * fmin(alpha, 1.0f) : 0.0f, MP_SSS_ROUGHNESS, &alpha_t);
  int cos_i = mp_sss_cell(cos_place, MP_SSS_COSINES, &cos_t);
  float3 r;
  r.x = radius.x < MP_SSS_MIN_RADIUS ? 1.0f : mp_sss_channel(albedo.x, model, eta_i, eta_t, alpha_i, alpha_t, cos_i, cos_t);
  r.y = radius.y < MP_SSS_MIN_RADIUS ? 1.0f : mp_sss_channel(albedo.y, model, eta_i, eta_t, alpha_i, alpha_t, cos_i, cos_t);
  r.z = radius.z < MP_SSS_MIN_RADIUS ? 1.0f : mp_sss_channel(albedo.z, model, eta_i, eta_t, alpha_i, alpha_t, cos_i, cos_t);
  return r;
}

/* As a 4.x walk (model MP_SSS_*) returns it: w (Color times the weight
 * above) scaled per channel by the walk's ratio for that Color (albedo), the
 * view's cosine nv to the normal, the entry's GGX roughness and IOR and the
 * radius (mp_subsurface_ratio). */
MP_INLINE void mp_add_subsurface_walk(MpSurface* s, float3 w, float3 albedo, float3 radius, float nv, float roughness,
                                      float ior, int model, int slot) {
  float3 a = mp_clamp_weight(albedo);
  a = MP_F3(fmin(a.x, 1.0f), fmin(a.y, 1.0f), fmin(a.z, 1.0f));
  float3 ratio = mp_subsurface_ratio(model, a, radius, nv, roughness, ior);
  mp_surface_add(s, mp_closure(MP_CLOSURE_SUBSURFACE, mp_clamp_weight(w) * ratio, slot, 0.0f, 0.0f));
}

#endif
