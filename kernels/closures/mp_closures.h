/* A surface as a weighted sum of closures, the way Cycles shades a shader
 * tree: a material program adds one closure per BSDF node reached through
 * Mix and Add Shader nodes (weights multiply down the tree), the Principled
 * BSDF adds its layers (mp_principled.h), and mp_shade_closures lights the
 * sum with every lamp and the world. Compiles as OpenCL C and C++ (include
 * mp_compat.h first).
 *
 * Each closure reads one of a few normals (slots): slot 0 is the surface's
 * shading normal (bumped where a bump-only displacement tilts it); a BSDF's
 * own Normal input or Coat Normal takes another. Normals are in the
 * program's object space while the program runs and in camera space when
 * shading (mp_surface_to_camera). */
#ifndef MP_CLOSURES_H
#define MP_CLOSURES_H

#include "core/mp_compat.h"

/* Thin film (mp_thin_film.h) costs registers in every shading kernel that
 * compiles it (12% of the Principled BSDF's shade time on an H100), so an
 * OpenCL program has it only where its material asks for it
 * (MP_NODE_USES_THIN_FILM, defined ahead of the headers); host code always
 * has it. Without it closures never carry a film. */
#if !defined(__OPENCL_VERSION__) || defined(MP_NODE_USES_THIN_FILM)
#define MP_THIN_FILM 1
#endif

/* Subsurface's random-walk table (mp_subsurface.h) likewise: only programs
 * whose material walks (MP_NODE_USES_SUBSURFACE_WALK) and the host. */
#if !defined(__OPENCL_VERSION__) || defined(MP_NODE_USES_SUBSURFACE_WALK)
#define MP_SUBSURFACE_WALK 1
#endif

/* Subsurface models (MpPrincipled.subsurface_model, mp_add_subsurface_walk). */
#define MP_SSS_LAMBERT 0 /* 3.x, Christensen-Burley */
#define MP_SSS_WALK 1    /* 4.x Random Walk */
#define MP_SSS_SKIN 2    /* 4.x Random Walk (Skin) */

#define MP_MAX_CLOSURES 10
#define MP_MAX_CLOSURE_NORMALS 4

/* Closure kinds. */
#define MP_CLOSURE_DIFFUSE 1      /* Lambert, or Oren-Nayar with a = sigma (EON: multiscatter, f82 = albedo) */
#define MP_CLOSURE_TRANSLUCENT 2  /* Lambert from the other side */
#define MP_CLOSURE_GLOSSY 3       /* GGX reflection; a, b = alpha_x, alpha_y */
#define MP_CLOSURE_REFRACTION 4   /* GGX transmission; a = alpha, b = IOR */
#define MP_CLOSURE_SHEEN 5        /* a = roughness; fresnel: MP_SHEEN_* */
#define MP_CLOSURE_TOON_DIFFUSE 6 /* a = size, b = smooth */
#define MP_CLOSURE_TOON_GLOSSY 7
#define MP_CLOSURE_SUBSURFACE 8   /* Lambert, of the random walk's albedo from 4.x on (mp_subsurface.h) */
#define MP_CLOSURE_CLEARCOAT 9    /* Principled 3.x's clearcoat: GTR1, IOR 1.5; a = b = alpha */
#define MP_CLOSURE_PHONG 10       /* RenderMan's plastic specular, (n.h)^(1/a) per unit irradiance */
#define MP_CLOSURE_HAIR 11        /* Principled Hair (Chiang); fields in mp_hair.h */
#define MP_CLOSURE_HAIR_REFLECTION 12   /* Hair BSDF's components (mp_hair.h) */
#define MP_CLOSURE_HAIR_TRANSMISSION 13

/* How a glossy closure's Fresnel term is computed. */
#define MP_FRESNEL_NONE 0       /* weight as it is (Glossy BSDF) */
#define MP_FRESNEL_SCHLICK 1    /* f0 + (1 - f0)(1 - cos)^5 (Principled before 4.0, in place of its rescaled dielectric curve) */
#define MP_FRESNEL_DIELECTRIC 2 /* exact dielectric of IOR f0.x, scaled by tint = f82 (weight) */
#define MP_FRESNEL_F82 3        /* conductor: Schlick from f0 with Hoffman's F82 tint (Principled 4.x metal) */
#define MP_FRESNEL_GENERALIZED 4 /* dielectric of IOR f82.x remapped to run from f0 (a colour) to 1 */

/* Sheen models. */
#define MP_SHEEN_ASHIKHMIN 0    /* Velvet BSDF (3.x) and Sheen BSDF's Ashikhmin */
#define MP_SHEEN_MICROFIBER 1   /* Sheen BSDF's Microfiber and Principled 4.x */
#define MP_SHEEN_PRINCIPLED_V1 2 /* Principled 3.x: Schlick weight (1 - cos)^5 on a diffuse-like lobe */

typedef struct {
  float3 weight;
  float3 f0;      /* glossy: Fresnel at normal incidence, or (IOR, 0, 0); diffuse: the weight of
                     ambient and world light (RenderMan's Ka; the weight itself for Blender's) */
  float3 f82;     /* glossy: F82 tint (MP_FRESNEL_F82) or (F0 target, 0, 0) (generalized) */
  float3 tangent; /* glossy: anisotropy direction (zero: isotropic) */
  float a, b;
  int kind;
  int fresnel;    /* glossy: MP_FRESNEL_*; sheen: MP_SHEEN_* */
  int slot;       /* normal slot */
  int multiscatter;
  float film, film_ior; /* glossy: a thin film's thickness (nm; 0: none) and IOR (mp_thin_film.h) */
} MpClosure;

typedef struct {
  MpClosure c[MP_MAX_CLOSURES];
  int count;
  float3 normal[MP_MAX_CLOSURE_NORMALS];
  int normal_mode[MP_MAX_CLOSURE_NORMALS]; /* MP_NORMAL_* of mp_node_lib.h, 0 for the surface's */
  int normals;
  float3 emission;
  float3 transparent; /* Transparent BSDF weight: 1 - its average is the alpha */
  float holdout;      /* Holdout weight (average): the part of the alpha cut out of the image */
  int dropped;        /* closures beyond MP_MAX_CLOSURES */
} MpSurface;

/* How a normal was set (MpSurface.normal_mode): as the surface's shading
 * normal (bump-only displacement) or through a BSDF's Normal input, which
 * Cycles keeps from reflecting the view direction below the surface. */
#define MP_NORMAL_SET 1
#define MP_NORMAL_INPUT 2
/* The same as Blender 4.0 and later shade it (mp_shade_closures), with and
 * without the material's Bump Map Correction. */
#define MP_NORMAL_INPUT_V4 3
#define MP_NORMAL_INPUT_V4_UNCORRECTED 4

MP_INLINE void mp_surface_init(MpSurface* s, float3 n) {
  s->count = 0;
  s->normals = 1;
  s->normal[0] = n;
  s->normal_mode[0] = 0;
  s->emission = MP_F3(0.0f, 0.0f, 0.0f);
  s->transparent = MP_F3(0.0f, 0.0f, 0.0f);
  s->holdout = 0.0f;
  s->dropped = 0;
}

/* The surface's shading normal replaced (bump-only displacement). */
MP_INLINE void mp_surface_set_normal(MpSurface* s, float3 n) {
  s->normal[0] = n;
  s->normal_mode[0] = MP_NORMAL_SET;
}

/* The slot of normal n set through a BSDF input (mode MP_NORMAL_INPUT*),
 * shared with an earlier closure's when equal. */
MP_INLINE int mp_surface_normal_slot(MpSurface* s, float3 n, int mode) {
  for (int k = 1; k < s->normals; ++k)
    if (s->normal_mode[k] == mode && s->normal[k].x == n.x && s->normal[k].y == n.y && s->normal[k].z == n.z)
      return k;
  if (s->normals == MP_MAX_CLOSURE_NORMALS) return 0;
  s->normal[s->normals] = n;
  s->normal_mode[s->normals] = mode;
  return s->normals++;
}

MP_INLINE int mp_weight_zero(float3 w) { return !(fmax(fmax(fabs(w.x), fabs(w.y)), fabs(w.z)) > 0.0f); }

MP_INLINE MpClosure mp_closure(int kind, float3 weight, int slot, float a, float b) {
  MpClosure c;
  c.weight = weight;
  c.f0 = MP_F3(0.0f, 0.0f, 0.0f);
  c.f82 = c.f0;
  c.tangent = c.f0;
  c.a = a;
  c.b = b;
  c.kind = kind;
  c.fresnel = 0;
  c.slot = slot;
  c.multiscatter = 0;
  c.film = 0.0f;
  c.film_ior = 1.0f;
  return c;
}

/* Closures of no weight (a Mix factor of 0 or 1, a black colour) cost
 * nothing; past MP_MAX_CLOSURES a closure is dropped and counted. */
MP_INLINE void mp_surface_add(MpSurface* s, MpClosure c) {
  if (!(isfinite(c.weight.x) && isfinite(c.weight.y) && isfinite(c.weight.z))) return;
  if (mp_weight_zero(c.weight) && !(c.kind == MP_CLOSURE_DIFFUSE && !mp_weight_zero(c.f0))) return;
  if (s->count == MP_MAX_CLOSURES) {
    s->dropped++;
    return;
  }
  s->c[s->count++] = c;
}

MP_INLINE float3 mp_clamp_weight(float3 w) {
  return MP_F3(fmax(w.x, 0.0f), fmax(w.y, 0.0f), fmax(w.z, 0.0f));
}

MP_INLINE void mp_add_diffuse(MpSurface* s, float3 w, int slot, float roughness) {
  MpClosure c = mp_closure(MP_CLOSURE_DIFFUSE, mp_clamp_weight(w), slot, clamp(roughness, 0.0f, 1.0f), 0.0f);
  c.f0 = c.weight;
  mp_surface_add(s, c);
}
/* A rough diffuse lobe as Cycles 4.3 and later shade it: Oren-Nayar plus
 * EON's multiple scattering (mp_eon_ms), which depends on the albedo
 * `color` (kept in f82; `multiscatter` marks the lobe). fmin/fmax rather
 * than clamp: a NaN input (a texture's) reads as 0, where clamp leaves it
 * undefined. */
MP_INLINE void mp_add_diffuse_eon(MpSurface* s, float3 w, float3 color, int slot, float roughness) {
  MpClosure c = mp_closure(MP_CLOSURE_DIFFUSE, mp_clamp_weight(w), slot, fmin(fmax(roughness, 0.0f), 1.0f), 0.0f);
  c.f0 = c.weight;
  float3 albedo = mp_clamp_weight(color);
  c.f82 = MP_F3(fmin(albedo.x, 1.0f), fmin(albedo.y, 1.0f), fmin(albedo.z, 1.0f));
  c.multiscatter = 1;
  mp_surface_add(s, c);
}
MP_INLINE void mp_add_translucent(MpSurface* s, float3 w, int slot) {
  mp_surface_add(s, mp_closure(MP_CLOSURE_TRANSLUCENT, mp_clamp_weight(w), slot, 0.0f, 0.0f));
}
/* Subsurface scattering as Blender 3.x's walk (and Christensen-Burley)
 * returns it: Lambert of its Color. */
MP_INLINE void mp_add_subsurface(MpSurface* s, float3 w, int slot) {
  mp_surface_add(s, mp_closure(MP_CLOSURE_SUBSURFACE, mp_clamp_weight(w), slot, 0.0f, 0.0f));
}
MP_INLINE void mp_add_emission(MpSurface* s, float3 w) { s->emission += w; }
MP_INLINE void mp_add_transparent(MpSurface* s, float3 w) { s->transparent += mp_clamp_weight(w); }
/* Holdout: as Cycles, its weight's average leaves the image transparent
 * there (alpha and colour 0) while the surface still hides what lies
 * behind it. */
MP_INLINE void mp_add_holdout(MpSurface* s, float3 w) {
  float3 c = mp_clamp_weight(w);
  s->holdout += (c.x + c.y + c.z) * (1.0f / 3.0f);
}

/* GGX reflection of roughness r (alpha = r^2) stretched by anisotropy
 * along `tangent`, as Cycles' Glossy BSDF maps them (4.0 and later; 3.x's
 * Anisotropic BSDF the same): alpha_x = alpha (1 - a), alpha_y =
 * alpha / (1 - a) for a >= 0, and alpha / (1 + a), alpha (1 + a) for a < 0. */
MP_INLINE void mp_add_glossy(MpSurface* s, float3 w, int slot, float roughness, float anisotropy, float3 tangent,
                             int fresnel, float3 f0, float3 f82, int multiscatter) {
  float r = clamp(roughness, 0.0f, 1.0f);
  float alpha = r * r, ax = alpha, ay = alpha;
  float an = clamp(anisotropy, -0.99f, 0.99f);
  if (an != 0.0f && dot(tangent, tangent) > 0.0f) {
    if (an < 0.0f) ax = alpha / (1.0f + an), ay = alpha * (1.0f + an);
    else ax = alpha * (1.0f - an), ay = alpha / (1.0f - an);
  } else
    tangent = MP_F3(0.0f, 0.0f, 0.0f);
  MpClosure c = mp_closure(MP_CLOSURE_GLOSSY, mp_clamp_weight(w), slot, ax, ay);
  c.tangent = tangent;
  c.fresnel = fresnel;
  /* A dielectric's IOR (f0.x) from a node input may be anything: 0, less or
   * NaN reads as the smallest IOR, as the refraction lobe reads it. */
  if (fresnel == MP_FRESNEL_DIELECTRIC) f0.x = fmax(f0.x, 1e-5f);
  c.f0 = f0;
  c.f82 = f82;
  c.multiscatter = multiscatter;
  mp_surface_add(s, c);
}

/* Refraction: all of its weight through the surface (Refraction BSDF), or
 * (glass = 1) what the dielectric Fresnel term does not reflect. tint: what
 * each further surface along the path through the object multiplies by
 * (Cycles evaluates the closure again at every hit; w holds the first
 * surface's share, tint included). */
MP_INLINE void mp_add_refraction_tinted(MpSurface* s, float3 w, float3 tint, int slot, float roughness, float ior,
                                        int glass) {
  float r = clamp(roughness, 0.0f, 1.0f);
  MpClosure c = mp_closure(MP_CLOSURE_REFRACTION, mp_clamp_weight(w), slot, r * r, fmax(ior, 1e-5f));
  c.fresnel = glass;
  c.f0 = mp_clamp_weight(tint);
  mp_surface_add(s, c);
}

/* Untinted past the first surface (programs written before the tint). */
MP_INLINE void mp_add_refraction(MpSurface* s, float3 w, int slot, float roughness, float ior, int glass) {
  mp_add_refraction_tinted(s, w, MP_F3(1.0f, 1.0f, 1.0f), slot, roughness, ior, glass);
}

/* Glass: dielectric reflection and refraction split by the exact Fresnel
 * term (each closure applies its share); w = weight * colour, tint = the
 * colour. */
MP_INLINE void mp_add_glass_tinted(MpSurface* s, float3 w, float3 tint, int slot, float roughness, float ior,
                                   int multiscatter) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f);
  mp_add_glossy(s, w, slot, roughness, 0.0f, MP_F3(0.0f, 0.0f, 0.0f), MP_FRESNEL_DIELECTRIC, MP_F3(ior, 0.0f, 0.0f),
                one, multiscatter);
  mp_add_refraction_tinted(s, w, tint, slot, roughness, ior, 1);
}

MP_INLINE void mp_add_glass(MpSurface* s, float3 w, int slot, float roughness, float ior, int multiscatter) {
  mp_add_glass_tinted(s, w, MP_F3(1.0f, 1.0f, 1.0f), slot, roughness, ior, multiscatter);
}

MP_INLINE void mp_add_sheen(MpSurface* s, float3 w, int slot, float roughness, int model) {
  MpClosure c = mp_closure(MP_CLOSURE_SHEEN, mp_clamp_weight(w), slot, clamp(roughness, 0.0f, 1.0f), 0.0f);
  c.fresnel = model;
  mp_surface_add(s, c);
}

MP_INLINE void mp_add_toon(MpSurface* s, float3 w, int slot, float size, float smooth, int glossy) {
  mp_surface_add(s, mp_closure(glossy ? MP_CLOSURE_TOON_GLOSSY : MP_CLOSURE_TOON_DIFFUSE, mp_clamp_weight(w), slot,
                               clamp(size, 0.0f, 1.0f), clamp(smooth, 0.0f, 1.0f)));
}

/* Geometric specular antialiasing (Kaplanyan, Hill, Patney and Lefohn
 * 2016; Tokuyoshi and Kaplanyan 2019): a highlight narrower than a
 * micropolygon, shaded at its vertices and interpolated between them,
 * would alias; the spread of the normal across the micropolygon (n to its
 * neighbours one step along u and v) is added to a sharp lobe's alpha^2
 * instead, as the pixel filter would have blurred it: variance
 * 1/(2 pi) (|dn_u|^2 + |dn_v|^2), at most 0.18. */
MP_INLINE float mp_normal_spread2(float3 n, float3 nu, float3 nv) {
  float3 du = nu - n, dv = nv - n;
  float variance = (0.5f / 3.14159265358979f) /* 1 / (2 pi) */ * (dot(du, du) + dot(dv, dv));
  return isfinite(variance) ? fmin(2.0f * variance, 0.18f) : 0.0f;
}

/* The surface's coverage: 1 - the Transparent weight's average (Cycles'
 * alpha), in [0, 1]. */
MP_INLINE float mp_surface_alpha(const MpSurface* s) {
  float t = (s->transparent.x + s->transparent.y + s->transparent.z) * (1.0f / 3.0f);
  return clamp(1.0f - t, 0.0f, 1.0f);
}

/* The share of a surface's covered samples that are held out: Cycles'
 * alpha is 1 - transparent - holdout, and a covered sample stays in the
 * image with probability alpha (stochastic opacity), so held out among those
 * with probability holdout / alpha. */
MP_INLINE float mp_surface_holdout_share(const MpSurface* s, float alpha) {
  return alpha > 0.0f ? clamp(s->holdout / alpha, 0.0f, 1.0f) : 0.0f;
}

#endif
