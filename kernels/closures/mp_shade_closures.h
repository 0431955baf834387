/* Lighting a sum of closures (mp_closures.h) at a grid vertex: every lamp
 * with its shadow, and the world's irradiance and prefiltered glossy maps
 * with its probes' shadows, for each closure. Everything in camera space.
 * Compiles as OpenCL C and C++. */
#ifndef MP_SHADE_CLOSURES_H
#define MP_SHADE_CLOSURES_H

#include "core/mp_compat.h"
#include "closures/mp_bsdf.h"
#include "closures/mp_closures.h"
#include "closures/mp_hair.h"
#include "closures/mp_principled.h"
#include "closures/mp_shading.h"
#include "geometry/mp_refract_trace.h"

/* A closure reads its normal slot as a diffuse lobe (the normal as it is,
 * shadowed by the smooth surface) or as a glossy one (kept from reflecting
 * below the surface). */
MP_INLINE int mp_closure_is_glossy(int kind) {
  return kind == MP_CLOSURE_GLOSSY || kind == MP_CLOSURE_REFRACTION || kind == MP_CLOSURE_TOON_GLOSSY ||
         kind == MP_CLOSURE_CLEARCOAT || kind == MP_CLOSURE_PHONG;
}

/* The light a lamp gives a surface of normal n at p, as a factor of its
 * colour (irradiance per unit colour); `l` is the direction to it. */
MP_INLINE float mp_lamp_factor(MP_GLOBAL const DeviceLight* lt, int type, float3 p, float3 n, float3 to_light,
                               float d2, float3* l) {
  if (type == MP_LIGHT_AREA) return mp_area_irradiance(lt, p, n, l);
  if (type == MP_LIGHT_DISTANT) return fmax(dot(n, *l), 0.0f);
  if (lt->cone[3] > 0.0f) return mp_sized_light_factor(lt, to_light, d2, n);
  return fmax(dot(n, *l), 0.0f) / d2;
}

/* A hair closure's lobes towards v from direction l (mp_hair.h). */
MP_INLINE float3 mp_hair_lobes(const MpClosure* c, float3 n, float3 l, float3 v) {
  if (c->kind == MP_CLOSURE_HAIR) return mp_hair_chiang(c, n, l, v);
  float f = mp_hair_kajiya(c, n, l, v);
  return MP_F3(f, f, f);
}

/* A hair closure under an area light: its lobes, narrow beside a large
 * light, summed over a 4 x 4 grid of points on the light (those inside an
 * ellipse's), each weighted by the solid angle of its share of the area,
 * rather than read towards the light's centre alone (16 % too dark for a
 * 1 m light 4 m from a fibre of roughness 0.3). */
MP_INLINE float3 mp_hair_area_light(const MpClosure* c, float3 n, float3 v, MP_GLOBAL const DeviceLight* lt,
                                    float3 p) {
  float3 ctr = mp_light_f3(lt->position), u = mp_light_f3(lt->axis_u), w = mp_light_f3(lt->axis_v);
  float3 dir = normalize(mp_light_f3(lt->direction));
  int ellipse = lt->axis_u[3] == (float)MP_AREA_ELLIPSE;
  float area = length(u) * length(w) * (ellipse ? MP_PI : 4.0f);
  float3 sum = MP_F3(0.0f, 0.0f, 0.0f);
  int count = 0;
  /* Chiang's lobes: the view's part once for all 16 points. */
  int chiang = c->kind == MP_CLOSURE_HAIR;
  MpHairView view;
  if (chiang) view = mp_hair_chiang_view(c, n, v);
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) {
      float a = 0.5f * (float)i - 0.75f, b = 0.5f * (float)k - 0.75f;
      if (ellipse && a * a + b * b > 1.0f) continue;
      ++count;
      float3 q = ctr + a * u + b * w - p;
      float d2 = dot(q, q);
      if (!(d2 > 0.0f)) continue;
      float3 l = q / sqrt(d2);
      float facing = -dot(l, dir); /* the light emits along +dir */
      if (facing > 0.0f) sum += (chiang ? mp_hair_chiang_from(&view, l) : mp_hair_lobes(c, n, l, v)) * (facing / d2);
    }
  return count > 0 ? sum * (area / (float)count) : sum;
}

/* Readies a surface (normals in camera space) for mp_shade_closures at
 * camera-space point p: widens its GGX lobes by a normal spread^2
 * (mp_normal_spread2), and reads each microfiber sheen's transform and
 * albedo for the view into its f0 (mp_microfiber_sheen_ltc), so that no
 * table is read per lamp. */
MP_INLINE void mp_surface_prepare(MpSurface* s, float spread2, float3 p, int ortho) {
  float3 v = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : normalize(-p);
  for (int i = 0; i < s->count; ++i) {
    MpClosure* c = &s->c[i];
#ifdef MP_MICROFIBER_SHEEN
    if (c->kind == MP_CLOSURE_SHEEN && c->fresnel == MP_SHEEN_MICROFIBER)
      c->f0 = mp_microfiber_sheen_ltc(fabs(dot(s->normal[c->slot], v)), c->a);
#endif
    if (!(spread2 > 0.0f) || (c->kind != MP_CLOSURE_GLOSSY && c->kind != MP_CLOSURE_CLEARCOAT)) continue;
    c->a = fmin(sqrt(c->a * c->a + spread2), 1.0f);
    c->b = fmin(sqrt(c->b * c->b + spread2), 1.0f);
  }
}

/* A closure carries a thin film (never where the program compiled none). */
#ifdef MP_THIN_FILM
#define MP_FILM_ON(c) ((c)->film > 0.0f)
#else
#define MP_FILM_ON(c) 0
#endif

/* The glossy closure's Fresnel term at the cosine c between the view and
 * the half vector; `back`: seen from inside, where a dielectric's relative
 * IOR is inverted. */
MP_INLINE float3 mp_closure_fresnel(const MpClosure* c, float cos_vh, int back) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f);
#ifdef MP_THIN_FILM
  if (c->film > 0.0f) {
    /* A thin film (mp_thin_film.h) over the dielectric or metal. */
    if (c->fresnel == MP_FRESNEL_GENERALIZED)
      return mp_film_dielectric(cos_vh, c->film, c->film_ior, back ? 1.0f / c->f82.x : c->f82.x, c->f0);
    if (c->fresnel == MP_FRESNEL_F82) return mp_film_metal(cos_vh, c->film, c->film_ior, c->f0, c->f82);
  }
#endif
  if (c->fresnel == MP_FRESNEL_SCHLICK) return c->f0 + (one - c->f0) * mp_schlick_weight(cos_vh);
  if (c->fresnel == MP_FRESNEL_DIELECTRIC) return c->f82 * mp_fresnel_dielectric(cos_vh, back ? 1.0f / c->f0.x : c->f0.x);
  if (c->fresnel == MP_FRESNEL_GENERALIZED) {
    /* The dielectric curve of IOR f82.x remapped to run from f0 (a colour:
     * its reflectance at normal incidence times the specular tint) to 1
     * (Cycles' generalised Schlick with a negative exponent). */
    float f0 = mp_f0_from_ior(c->f82.x);
    float eta = back ? 1.0f / c->f82.x : c->f82.x;
    float t = f0 < 1.0f ? clamp((mp_fresnel_dielectric(cos_vh, eta) - f0) / (1.0f - f0), 0.0f, 1.0f) : 1.0f;
    return c->f0 + (one - c->f0) * t;
  }
  if (c->fresnel == MP_FRESNEL_F82) /* Hoffman's F82-tint (mp_bsdf.h) */
    return MP_F3(mp_f82(cos_vh, c->f0.x, mp_f82_tint_b(c->f0.x, c->f82.x)),
                 mp_f82(cos_vh, c->f0.y, mp_f82_tint_b(c->f0.y, c->f82.y)),
                 mp_f82(cos_vh, c->f0.z, mp_f82_tint_b(c->f0.z, c->f82.z)));
  return one;
}

/* Multiple scattering's gain on a glossy lobe of single scattering: 1 / E,
 * E its albedo for a Fresnel term of 1 (the energy compensation Cycles
 * applies to Multiscatter GGX, without its Fresnel-tinted share). */
MP_INLINE float mp_closure_multiscatter(const MpClosure* c, float nv) {
  if (!c->multiscatter) return 1.0f;
  float r = sqrt(0.5f * (c->a + c->b));
  float2 ab = mp_ggx_albedo(r, fmax(nv, 1e-4f));
  return 1.0f / fmax(ab.x + ab.y, 1e-3f);
}

/* The glossy closure's directional albedo against the world, for the split
 * sum: the lobe's albedo split for the Fresnel term (mp_ggx_albedo's
 * table), with multiple scattering's gain where asked. */
MP_INLINE float3 mp_closure_glossy_albedo(const MpClosure* c, float nv) {
  float r = sqrt(0.5f * (c->a + c->b));
  float2 ab = mp_ggx_albedo(r, fmax(nv, 1e-4f));
  float e = fmax(ab.x + ab.y, 1e-3f);
  float3 albedo = MP_F3(e, e, e);
  if (MP_FILM_ON(c) && (c->fresnel == MP_FRESNEL_GENERALIZED || c->fresnel == MP_FRESNEL_F82)) {
    /* A film's colour changes too quickly with the angle for a split: its
     * reflectance along the view (where a sharp lobe reflects the world
     * from) times the lobe's albedo. */
    albedo = albedo * mp_closure_fresnel(c, clamp(nv, 0.0f, 1.0f), 0);
  } else if (c->fresnel != MP_FRESNEL_NONE) {
    /* Schlick's split: f0 a + b; for the exact and rescaled dielectric curves
     * the same with their value at normal incidence. */
    float3 f0 = c->fresnel == MP_FRESNEL_DIELECTRIC ? c->f82 * mp_f0_from_ior(c->f0.x) : c->f0;
    float3 f90 = c->fresnel == MP_FRESNEL_DIELECTRIC ? c->f82 : MP_F3(1.0f, 1.0f, 1.0f);
    albedo = f0 * ab.x + f90 * ab.y;
  }
  return albedo * mp_closure_multiscatter(c, nv);
}

/* A sheen closure's lobe (f cos) and its directional albedo. */
MP_INLINE float mp_sheen_albedo(const MpClosure* c, float nv) {
  /* Principled 3.x: (1 - l.h)^5 nl integrated over the hemisphere is
   * 0.0003 at normal view, 0.016 at nv = 0.5 and 0.048 at 0.2; 0.125 (1 -
   * nv)^3 follows that within a third. The Charlie lobe's albedo stands in
   * for the velvet lobe's. */
  if (c->fresnel == MP_SHEEN_PRINCIPLED_V1) {
    float t = 1.0f - clamp(nv, 0.0f, 1.0f);
    return 0.125f * t * t * t;
  }
  return c->fresnel == MP_SHEEN_ASHIKHMIN ? mp_charlie_sheen_albedo(nv, c->a) : c->f0.z;
}
MP_INLINE float mp_closure_sheen(const MpClosure* c, float3 n, float3 l, float3 v) {
  if (c->fresnel == MP_SHEEN_PRINCIPLED_V1) {
    if (!(dot(n, v) > 0.0f)) return 0.0f;
    float3 h = normalize(l + v);
    return mp_schlick_weight(fmax(dot(l, h), 0.0f)) * fmax(dot(n, l), 0.0f);
  }
  if (c->fresnel == MP_SHEEN_ASHIKHMIN) return mp_velvet(n, l, v, c->a);
  return mp_microfiber_sheen_lobe(n, l, v, c->f0);
}

/* The direction the view leaves a closed object refracting it (relative
 * IOR ior; `back`: seen from inside): refracted in, and out again as
 * through a sphere, whose far side bends the ray by as much again in the
 * same sense; from inside, one interface. Also the share that passes:
 * (1 - F) at each side for glass (fresnel), everything otherwise. Returns 0
 * under total internal reflection. */
MP_INLINE int mp_refracted_exit(float3 n, float3 v, float ior, int back, int fresnel, float3* out, float* through) {
  float eta = back ? ior : 1.0f / ior;
  float cos_i = dot(n, v);
  float3 d = -v, t;
  if (!mp_refract_dir(d, n, cos_i, eta, &t)) return 0;
  float fr = fresnel ? mp_fresnel_dielectric(cos_i, back ? 1.0f / ior : ior) : 0.0f;
  *through = 1.0f - fr;
  if (!back) {
    float ct = clamp(dot(t, d), -1.0f, 1.0f);
    float3 u = t - ct * d;
    float ul = length(u);
    if (ul > 1e-6f) {
      float dev = acos(ct);
      t = cos(2.0f * dev) * d + sin(2.0f * dev) * (u / ul);
    }
    *through *= 1.0f - fr;
  }
  *out = t;
  return 1;
}

/* The world seen through the object along the paths a refraction
 * closure c sends the view on (mp_refract_paths): into the surface at p
 * (normal n facing the viewer, `back` seen from inside), then through the
 * object's proxy; each path that leaves reads the world's prefiltered map
 * along its direction, blurred by the closure's roughness once per
 * surface it crossed. Per unit of c's weight. */
MP_INLINE float3 mp_refracted_world(const MpRefractScene* refract, float3 p, float3 n, float3 v, int back,
                                    const MpClosure* c, MP_GLOBAL const DeviceLight* world,
                                    MP_GLOBAL const float4* world_glossy) {
  float3 zero = MP_F3(0.0f, 0.0f, 0.0f);
  float ior = c->b, eta = back ? ior : 1.0f / ior;
  float cos_i = clamp(dot(n, v), 0.0f, 1.0f);
  float3 t;
  if (!mp_refract_dir(-v, n, cos_i, eta, &t)) return zero;
  t = normalize(t);
  float through = c->fresnel ? 1.0f - mp_fresnel_dielectric(cos_i, back ? 1.0f / ior : ior) : 1.0f;
  /* Past the proxy's tessellation error about p (a small share of its
   * size: the root's box), and off each surface hit by more than the
   * float error of camera-space positions. */
  float3 lo, hi;
  mp_refract_box(refract, &lo, &hi);
  float size = length(hi - lo);
  MpRefractExits ex;
  mp_refract_paths(refract, p, t, 2e-3f * size, fmax(1e-5f * size, 1e-6f * length(p)), ior, c->fresnel, c->f0, &ex);
  float3 sum = zero;
  float rough = sqrt(c->a);
  for (int i = 0; i < ex.count; ++i) {
    float r = fmin(rough * sqrt(0.5f * (float)(ex.interfaces[i] + 1)), 1.0f);
    sum += ex.weight[i] * mp_world_glossy(world_glossy, mp_env_to_world(world, ex.dir[i]), r);
  }
  /* Paths past the budgets see the world as a rough lobe about the view
   * would (rather than nothing). */
  if (ex.lost.x + ex.lost.y + ex.lost.z > 0.0f)
    sum += ex.lost * mp_world_glossy(world_glossy, mp_env_to_world(world, -v), 1.0f);
  return through * world->color[1] * sum;
}

/* Outgoing radiance at p towards the viewer from surface s (camera space,
 * normals already facing the viewer's side as ng does when `faced`). */
MP_INLINE float3 mp_shade_closures(float3 p, float3 ng, int faced, int ortho, const MpSurface* s,
                                   MP_GLOBAL const DeviceLight* lights, uint light_count,
                                   MP_GLOBAL const float4* world_glossy, const MpShadowQuery* shadow,
                                   const MpRefractScene* refract) {
  float3 zero = MP_F3(0.0f, 0.0f, 0.0f);
  float3 v = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : normalize(-p);
  int back = !faced && dot(ng, v) < 0.0f;
  /* A refracting object the camera is outside of is seen from outside
   * everywhere: grid vertices just past its silhouette (their micropolygons
   * still straddle it) are grazing front faces, not views from inside. */
  if (back && refract && !mp_refract_camera_inside(refract, ortho)) back = 0;
  float3 ngf = back ? -ng : ng;
  /* Each slot's normals: nf for glossy lobes, nd for diffuse ones. */
  float3 nf[MP_MAX_CLOSURE_NORMALS], nd[MP_MAX_CLOSURE_NORMALS];
  int used = 0, backlit = 0;
  for (int k = 0; k < s->normals; ++k) {
    int mode = s->normal_mode[k];
    float3 n = back ? -s->normal[k] : s->normal[k];
    nd[k] = n;
    nf[k] = mode >= MP_NORMAL_INPUT ? mp_valid_reflection_normal(ngf, v, n) : n;
    if (mode == MP_NORMAL_INPUT) nd[k] = nf[k];
  }
  int hair = 0, ribbon = shadow && shadow->ribbon;
  float fibre_radius = 0.0f;
  float3 fibre_axis = zero;
  for (int i = 0; i < s->count; ++i) {
    used |= 1 << s->c[i].slot;
    if (s->c[i].kind == MP_CLOSURE_TRANSLUCENT) backlit |= 1 << s->c[i].slot;
    if (mp_closure_is_hair(s->c[i].kind)) {
      hair = 1;
      if (s->c[i].film > fibre_radius) fibre_radius = s->c[i].film, fibre_axis = s->c[i].tangent;
    }
  }
  /* A ribbon's vertex sits at offset h = N . s across the strip (mp_ribbon.h,
   * s square to the fibre and the view), so the fibre's axis is a radius
   * times h back along s. */
  float3 axis_point = p;
  if (ribbon && shadow && fibre_radius > 0.0f) {
    float3 side = cross(fibre_axis, v);
    float ls = length(side);
    if (ls > 1e-12f) {
      side = side / ls;
      axis_point = p - (clamp(dot(ng, side), -1.0f, 1.0f) * fibre_radius) * side;
    }
  }
  float3 out = zero, ambient = zero;
  MP_GLOBAL const DeviceLight* world = 0;
  float3 mirror0 = 2.0f * dot(nf[0], v) * nf[0] - v;
  /* Probes weigh towards the mirror direction by a power that narrows with
   * the sharpest glossy lobe (the probes' soft shadows are as wide as their
   * regions: a sharp lobe should read the one it points into). */
  float sharp = 1.0f;
  for (int i = 0; i < s->count; ++i)
    if (s->c[i].kind == MP_CLOSURE_GLOSSY || s->c[i].kind == MP_CLOSURE_REFRACTION)
      sharp = fmax(sharp, fmin(1.0f / fmax(s->c[i].kind == MP_CLOSURE_GLOSSY ? 0.5f * (s->c[i].a + s->c[i].b)
                                                                              : s->c[i].a, 1e-3f), 32.0f));
  uint probe_index[MP_WORLD_PROBE_LOOKUPS];
  float probe_w[MP_WORLD_PROBE_LOOKUPS], probe_ws[MP_WORLD_PROBE_LOOKUPS], probe_wb[MP_WORLD_PROBE_LOOKUPS];
  int probes = 0;
  for (uint k = 0; k < light_count && s->count > 0; ++k) {
    MP_GLOBAL const DeviceLight* lt = lights + k;
    float3 cl = mp_light_f3(lt->color);
    int type = (int)lt->color[3];
    if (type == MP_LIGHT_AMBIENT) {
      ambient += cl;
      continue;
    }
    if (type == MP_LIGHT_ENVIRONMENT) world = lt;
    if (type == MP_LIGHT_ENVIRONMENT || type == MP_LIGHT_ENVIRONMENT_DATA) continue;
    if (type == MP_LIGHT_DISTANT && lt->axis_u[3] == MP_WORLD_PROBE) {
      float3 lp = -mp_light_f3(lt->direction);
      float w = (cl.x + cl.y + cl.z) * fmax(dot(nd[0], lp), 0.0f);
      float ws = (cl.x + cl.y + cl.z) * MP_POWR(fmax(dot(mirror0, lp), 0.0f), sharp);
      /* Translucent closures take light from behind. */
      float wb = backlit ? (cl.x + cl.y + cl.z) * fmax(-dot(nd[0], lp), 0.0f) : 0.0f;
      if (!(w + ws + wb > 0.0f)) continue;
      int at = probes < MP_WORLD_PROBE_LOOKUPS ? probes++ : MP_WORLD_PROBE_LOOKUPS;
      while (at > 0 && probe_w[at - 1] + probe_ws[at - 1] + probe_wb[at - 1] < w + ws + wb) {
        if (at < MP_WORLD_PROBE_LOOKUPS)
          probe_index[at] = probe_index[at - 1], probe_w[at] = probe_w[at - 1], probe_ws[at] = probe_ws[at - 1],
          probe_wb[at] = probe_wb[at - 1];
        --at;
      }
      if (at < MP_WORLD_PROBE_LOOKUPS) probe_index[at] = k, probe_w[at] = w, probe_ws[at] = ws, probe_wb[at] = wb;
      continue;
    }
    float3 to_light = zero, l = zero;
    float d2 = 1.0f;
    if (type == MP_LIGHT_DISTANT)
      l = -mp_light_f3(lt->direction);
    else if (type != MP_LIGHT_AREA) {
      to_light = mp_light_f3(lt->position) - p;
      d2 = fmax(dot(to_light, to_light), 1e-20f);
      l = to_light / sqrt(d2);
      if (type == MP_LIGHT_SPOT) cl *= mp_spot_mask(lt, p);
    }
    float ef[MP_MAX_CLOSURE_NORMALS], ed[MP_MAX_CLOSURE_NORMALS], eb[MP_MAX_CLOSURE_NORMALS];
    float any = 0.0f;
    for (int j = 0; j < s->normals; ++j) {
      ef[j] = ed[j] = eb[j] = 0.0f;
      if (!(used & (1 << j))) continue;
      ef[j] = mp_lamp_factor(lt, type, p, nf[j], to_light, d2, &l);
      ed[j] = s->normal_mode[j] >= MP_NORMAL_INPUT_V4 ? mp_lamp_factor(lt, type, p, nd[j], to_light, d2, &l) : ef[j];
      if (backlit & (1 << j)) eb[j] = mp_lamp_factor(lt, type, p, -nd[j], to_light, d2, &l);
      any += ef[j] + ed[j] + eb[j];
    }
    /* A fibre takes light from every side: the lamp's light per unit
     * radiance over its solid angle, as seen facing it. */
    float eh = hair ? mp_lamp_factor(lt, type, p, l, to_light, d2, &l) : 0.0f;
    any += eh;
    if (!(any > 0.0f) || !(cl.x > 0.0f || cl.y > 0.0f || cl.z > 0.0f)) continue;
    float3 cl_hair = cl;
    if (shadow) {
      /* A fibre's lobes take light through the fibre itself: where the
       * fibre hides the lamp from the vertex, as seen from just outside it
       * towards the lamp (its axis, then past its radius across it, from
       * where the way to the lamp stays outside it). */
      float3 across = l - fibre_axis * (dot(fibre_axis, l) / fmax(dot(fibre_axis, fibre_axis), 1e-20f));
      float la = length(across);
      /* A ribbon stands for the fibre, and the lights' maps hold it as a
       * strip through the axis facing each light: every vertex of it looks
       * from outside the fibre, on the lamp's side (a fibre does not shadow
       * itself, as in Cycles, whose shadow rays skip their own segment). */
      if (hair && ribbon && fibre_radius > 0.0f && la > 1e-3f)
        cl_hair *= mp_shadow_visibility(shadow->maps, k, axis_point + across * (1.05f * fibre_radius / la), l,
                                        shadow->footprint);
      else if (hair && fibre_radius > 0.0f && la > 1e-3f && dot(nd[0], l) < 0.0f)
        cl_hair *= mp_shadow_visibility(shadow->maps, k, p - nd[0] * fibre_radius + across * (1.05f * fibre_radius / la),
                                        l, shadow->footprint);
      else if (hair)
        cl_hair *= mp_shadow_visibility(shadow->maps, k, p, ribbon ? l : shadow->normal, shadow->footprint);
      /* A ribbon's vertex is compared on the plane square to the lamp (a
       * round fibre's surface faces every way; the strip's own plane, or
       * its rounded normal's, would tilt the comparison across the filter
       * into the neighbouring strands' depths). */
      cl *= mp_shadow_visibility(shadow->maps, k, p, ribbon ? l : shadow->normal, shadow->footprint);
    }
    for (int i = 0; i < s->count; ++i) {
      const MpClosure* c = &s->c[i];
      int j = c->slot, mode = s->normal_mode[j];
      float3 n = mp_closure_is_glossy(c->kind) ? nf[j] : nd[j];
      float e = mp_closure_is_glossy(c->kind) ? ef[j] : ed[j];
      float nl = dot(n, l);
      /* A BSDF's own normal: its diffuse light shadowed by the surface. */
      float shadowing = 1.0f;
      if (!mp_closure_is_glossy(c->kind) && mode == MP_NORMAL_INPUT) shadowing = mp_bump_shadowing(ngf, n, l);
      if (!mp_closure_is_glossy(c->kind) && mode >= MP_NORMAL_INPUT_V4)
        shadowing = mp_bump_shadowing_v4(ngf, n, l, mode == MP_NORMAL_INPUT_V4);
      float f = 0.0f; /* f cos / cos: the response per unit irradiance */
      float3 tint = MP_F3(1.0f, 1.0f, 1.0f);
      if (c->kind == MP_CLOSURE_TRANSLUCENT) {
        out += c->weight * (cl * (eb[j] * (1.0f / MP_PI)));
        continue;
      }
      if (mp_closure_is_hair(c->kind)) {
        out += c->weight * cl_hair * (type == MP_LIGHT_AREA ? mp_hair_area_light(c, nd[j], v, lt, p) : mp_hair_lobes(c, nd[j], l, v) * eh);
        continue;
      }
      if (!(e > 0.0f) || !(nl > 0.0f)) continue;
      float nv = fmax(dot(n, v), 1e-6f);
      if (c->kind == MP_CLOSURE_DIFFUSE) {
        f = c->fresnel ? mp_disney_diffuse(n, l, v, c->b) / nl
            : c->a > 0.0f ? mp_oren_nayar(n, l, v, c->a) / nl : 1.0f / MP_PI;
        /* EON's multiple scattering, added to the single-scattering lobe. */
        if (c->multiscatter && c->a > 0.0f && !c->fresnel)
          out += c->weight * mp_eon_ms(c->f82, c->a, nl, nv) * (cl * (e * shadowing));
      }
      else if (c->kind == MP_CLOSURE_SUBSURFACE)
        f = 1.0f / MP_PI;
      else if (c->kind == MP_CLOSURE_GLOSSY) {
        float3 tx, ty;
        mp_frame(n, c->tangent, &tx, &ty);
        f = mp_ggx_reflect(n, tx, ty, l, v, c->a, c->b) * mp_closure_multiscatter(c, nv);
        tint = mp_closure_fresnel(c, fmax(dot(v, normalize(l + v)), 0.0f), back);
      } else if (c->kind == MP_CLOSURE_PHONG)
        f = MP_POWR(fmax(dot(n, normalize(l + v)), 0.0f), 1.0f / fmax(c->a, 1e-4f)) / nl;
      else if (c->kind == MP_CLOSURE_CLEARCOAT)
        f = mp_clearcoat(n, l, v, c->a);
      else if (c->kind == MP_CLOSURE_SHEEN)
        f = mp_closure_sheen(c, n, l, v) / nl;
      else if (c->kind == MP_CLOSURE_TOON_DIFFUSE)
        f = mp_toon(nl, c->a, c->b) / nl;
      else if (c->kind == MP_CLOSURE_TOON_GLOSSY)
        f = dot(n, v) > 0.0f ? mp_toon(dot(2.0f * dot(n, v) * n - v, l), c->a, c->b) / nl : 0.0f;
      out += c->weight * tint * (cl * (e * f * shadowing));
    }
  }
  /* The world: irradiance for diffuse lobes, the prefiltered maps for
   * glossy ones, darkened by what its probes' shadows let through. */
  float vis = 1.0f, vis_s = 1.0f, vis_b = 1.0f;
  if (world) {
    float lit = 0.0f, total = 0.0f, lit_s = 0.0f, total_s = 0.0f, lit_b = 0.0f, total_b = 0.0f;
    for (int i = 0; i < probes; ++i) {
      float pv = shadow ? mp_shadow_visibility(shadow->maps, probe_index[i], p, shadow->normal, shadow->footprint)
                        : 1.0f;
      total += probe_w[i], lit += probe_w[i] * pv;
      total_s += probe_ws[i], lit_s += probe_ws[i] * pv;
      total_b += probe_wb[i], lit_b += probe_wb[i] * pv;
    }
    vis_b = total_b > 0.0f ? lit_b / total_b : 1.0f;
    vis = total > 0.0f ? lit / total : 1.0f;
    vis_s = total_s > 0.0f ? lit_s / total_s : vis;
  }
  for (int i = 0; i < s->count; ++i) {
    const MpClosure* c = &s->c[i];
    int j = c->slot;
    float3 n = mp_closure_is_glossy(c->kind) ? nf[j] : nd[j];
    float nv = fmax(dot(n, v), 1e-4f);
    float3 diffuse_world = zero, glossy_world = zero;
    if (c->kind == MP_CLOSURE_GLOSSY || c->kind == MP_CLOSURE_TOON_GLOSSY || c->kind == MP_CLOSURE_CLEARCOAT) {
      float3 r = 2.0f * dot(n, v) * n - v;
      float rough = c->kind == MP_CLOSURE_TOON_GLOSSY ? sqrt(c->a) : sqrt(0.5f * (c->a + c->b));
      float3 albedo = c->kind == MP_CLOSURE_TOON_GLOSSY ? MP_F3(1.0f, 1.0f, 1.0f) : mp_closure_glossy_albedo(c, nv);
      if (world) glossy_world = mp_world_glossy(world_glossy, mp_env_to_world(world, r), rough) * (vis_s * world->color[1]);
      out += c->weight * albedo * (glossy_world + ambient);
    } else if (c->kind == MP_CLOSURE_REFRACTION) {
      /* The world through the object, as environment-mapped refraction
       * did before ray tracing (mp_refracted_exit). */
      float3 t;
      float through;
      if (world && refract) {
        out += c->weight * mp_refracted_world(refract, p, n, v, back, c, world, world_glossy);
      } else if (world && mp_refracted_exit(n, v, c->b, back, c->fresnel, &t, &through)) {
        glossy_world = mp_world_glossy(world_glossy, mp_env_to_world(world, t), sqrt(c->a)) * world->color[1];
        out += c->weight * through * glossy_world;
      }
    } else if (mp_closure_is_hair(c->kind)) {
      /* Light from every side: the mean of the irradiance on both sides
       * over pi is the mean radiance arriving, times the colour the
       * parametrisation stands for (Hair BSDF: its weight, as each lobe
       * integrates to one). */
      if (world)
        diffuse_world = (mp_env_irradiance(world, n) + mp_env_irradiance(world, -n)) *
                        (0.5f / MP_PI * vis * world->color[0]);
      float3 albedo = c->kind == MP_CLOSURE_HAIR ? mp_hair_albedo(c) : MP_F3(1.0f, 1.0f, 1.0f);
      out += c->weight * albedo * (diffuse_world + ambient);
    } else if (c->kind != MP_CLOSURE_PHONG) {
      float3 dn = c->kind == MP_CLOSURE_TRANSLUCENT ? -n : n;
      if (world)
        diffuse_world = mp_env_irradiance(world, dn) * ((c->kind == MP_CLOSURE_TRANSLUCENT ? vis_b : vis) * world->color[0]);
      /* Light from every side reflected by the lobe: Lambert's all, a
       * rough diffuse lobe its directional albedo (with EON's multiple
       * scattering), a sheen its table's. */
      float3 albedo = MP_F3(1.0f, 1.0f, 1.0f);
      if (c->kind == MP_CLOSURE_SHEEN) albedo *= mp_sheen_albedo(c, nv);
      if (c->kind == MP_CLOSURE_DIFFUSE && c->a > 0.0f && !c->fresnel) {
        albedo *= mp_oren_nayar_albedo(nv, c->a);
        if (c->multiscatter) albedo += mp_eon_ms_albedo(c->f82, c->a, nv);
      }
      out += (c->kind == MP_CLOSURE_DIFFUSE ? c->f0 : c->weight) * albedo * (diffuse_world + ambient);
    }
  }
  return out + s->emission;
}

/* A material without a program (DeviceMaterial), as closures: Principled
 * ones as those of their constant inputs (their opacity is the
 * rasteriser's coverage); RenderMan's matte and plastic (RenderMan
 * Interface Specification 3.2, appendix A) as a diffuse closure whose lamp
 * light is Kd times the irradiance and whose ambient and world light is Ka
 * times theirs, plus for plastic a Phong lobe of Ks times the specular
 * colour; constant as its colour. spread2: the normal's spread across the
 * micropolygon (mp_normal_spread2). */
MP_INLINE float3 mp_shade_material(float3 p, float3 n, int faced, int ortho, const DeviceMaterial* m,
                                   MP_GLOBAL const DeviceLight* lights, uint light_count,
                                   MP_GLOBAL const float4* world_glossy, const MpShadowQuery* shadow, float spread2,
                                   const MpRefractScene* refract) {
  float3 zero = MP_F3(0.0f, 0.0f, 0.0f), one = MP_F3(1.0f, 1.0f, 1.0f);
  float3 cs = MP_F3(m->color[0], m->color[1], m->color[2]);
  float3 emission = MP_F3(m->emission[0], m->emission[1], m->emission[2]);
  int model = (int)m->color[3];
  if (model == MP_MODEL_CONSTANT) return cs + emission;
  MpSurface s;
  mp_surface_init(&s, n);
  if (model != MP_MODEL_PRINCIPLED) {
    MpClosure d = mp_closure(MP_CLOSURE_DIFFUSE, cs * (m->coeffs[1] * MP_PI), 0, 0.0f, 0.0f);
    d.f0 = cs * m->coeffs[0];
    mp_surface_add(&s, d);
    if (model == MP_MODEL_PLASTIC)
      mp_surface_add(&s, mp_closure(MP_CLOSURE_PHONG, MP_F3(m->specular[0], m->specular[1], m->specular[2]) *
                                                          m->coeffs[2], 0, m->coeffs[3], 0.0f));
    mp_add_emission(&s, emission);
    return mp_shade_closures(p, n, faced, ortho, &s, lights, light_count, world_glossy, shadow, refract);
  }
  float3 v = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : normalize(-p);
  MpPrincipled pr;
  pr.base_color = cs;
  pr.metallic = m->principled[0];
  pr.roughness = m->coeffs[3];
  pr.ior = 1.5f;
  pr.alpha = 1.0f;
  pr.specular = m->principled[1];
  pr.specular_tint = m->principled[2] > 0.0f ? one : zero;
  pr.anisotropy = pr.anisotropic_rotation = 0.0f;
  pr.tangent = zero;
  pr.transmission = pr.transmission_roughness = 0.0f;
  pr.coat = pr.coat_roughness = 0.0f;
  pr.coat_ior = 1.5f;
  pr.coat_tint = one;
  pr.sheen = pr.sheen_roughness = 0.0f;
  pr.sheen_tint = one;
  pr.subsurface = 0.0f;
  pr.subsurface_color = pr.subsurface_radius = zero;
  pr.subsurface_ior = 1.4f;
  pr.subsurface_model = MP_SSS_LAMBERT;
  pr.diffuse_roughness = 0.0f;
  pr.thin_film = 0.0f;
  pr.thin_film_ior = 1.33f;
  pr.film_on_metal = 0;
  pr.emission = emission;
  pr.slot = pr.coat_slot = 0;
  pr.nv = pr.coat_nv = fabs(dot(n, v));
  pr.v4 = m->principled[2] > 0.0f;
  int flags = (int)m->principled[3];
  pr.retro = flags & 1;
  pr.multiscatter = (flags >> 1) & 1;
  mp_add_principled(&s, one, &pr, n);
  mp_surface_prepare(&s, spread2, p, ortho);
  return mp_shade_closures(p, n, faced, ortho, &s, lights, light_count, world_glossy, shadow, refract);
}

#endif
