/* The Principled BSDF as the closures Cycles splits it into (mp_closures.h),
 * in Blender 4.x's layered form (v4 = 1: sheen over coat over metal,
 * glass, specular and diffuse, each layer passing down what its albedo
 * leaves) or 3.x's (v4 = 0: the Disney weights). Compiles as OpenCL C and C++. */
#ifndef MP_PRINCIPLED_H
#define MP_PRINCIPLED_H

#include "core/mp_compat.h"
#include "closures/mp_bsdf.h"
#include "closures/mp_closures.h"
#ifdef MP_THIN_FILM
#include "closures/mp_thin_film.h"
#endif
#include "closures/mp_world.h"
#ifdef MP_SUBSURFACE_WALK
#include "closures/mp_subsurface.h"
#endif

typedef struct {
  float3 base_color;
  float metallic, roughness, ior, alpha;
  float specular;      /* 4.x: Specular IOR Level; 3.x: Specular */
  float3 specular_tint; /* 4.x: a colour; 3.x: the amount in .x */
  float anisotropy, anisotropic_rotation;
  float3 tangent;       /* object space; zero: none */
  float transmission, transmission_roughness;
  float coat, coat_roughness, coat_ior;
  float3 coat_tint;
  float sheen, sheen_roughness;
  float3 sheen_tint;    /* 4.x: a colour; 3.x: the amount in .x */
  float subsurface;
  float3 subsurface_color; /* 3.x */
  float3 subsurface_radius; /* 4.x: Subsurface Radius times Scale */
  float subsurface_ior;     /* 4.x: Subsurface IOR (Random Walk (Skin)) */
  int subsurface_model;     /* 4.x: MP_SSS_* (mp_subsurface.h) */
  float3 emission;      /* colour times strength */
  int slot, coat_slot;  /* normal slots */
  float nv, coat_nv;    /* cosines between the view and those normals */
  int v4, multiscatter;
  int retro;            /* 3.x: Disney's diffuse with retro-reflection (a Diffuse BSDF's is Lambert) */
  float diffuse_roughness; /* 4.3 and later: Oren-Nayar's sigma for the diffuse base */
  float thin_film, thin_film_ior; /* 4.2 and later: thickness (nm) and IOR over the specular layer */
  int film_on_metal;              /* 5.0 and later: over the metal too */
} MpPrincipled;

MP_INLINE float mp_luminance(float3 c) { return 0.212671f * c.x + 0.71516f * c.y + 0.072169f * c.z; }

/* A conductor's reflectance at normal incidence from its IOR n and
 * extinction k, per channel. */
MP_INLINE float3 mp_conductor_f0(float3 n, float3 k) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f);
  float3 a = (n - one) * (n - one) + k * k, b = (n + one) * (n + one) + k * k;
  return MP_F3(b.x > 0.0f ? a.x / b.x : 0.0f, b.y > 0.0f ? a.y / b.y : 0.0f, b.z > 0.0f ? a.z / b.z : 0.0f);
}

/* The tangent turned about normal n by a fraction `rotation` of a turn. */
MP_INLINE float3 mp_rotate_tangent(float3 t, float3 n, float rotation) {
  if (rotation == 0.0f) return t;
  float a = 2.0f * MP_BSDF_PI * rotation;
  return t * cos(a) + cross(n, t) * sin(a) + n * dot(n, t) * (1.0f - cos(a));
}

/* What a layer reflects, as Cycles estimates it for layering: its lobe
 * taken as energy-preserving, the Fresnel term running from f0 to 1 by the
 * split sum's share b / (a + b) (mp_ggx_albedo). */
MP_INLINE float3 mp_layer_albedo(float3 f0, float roughness, float nv) {
  float2 ab = mp_ggx_albedo(roughness, fmax(nv, 1e-4f));
  float s = ab.y / fmax(ab.x + ab.y, 1e-4f);
  return f0 + (MP_F3(1.0f, 1.0f, 1.0f) - f0) * s;
}

/* What passes below a layer of albedo a: 1 - its largest channel (Cycles'
 * closure_layering_weight). */
MP_INLINE float mp_below(float3 a) { return clamp(1.0f - fmax(a.x, fmax(a.y, a.z)), 0.0f, 1.0f); }

MP_INLINE float3 mp_min3(float3 c, float m) { return MP_F3(fmin(c.x, m), fmin(c.y, m), fmin(c.z, m)); }

/* A GGX lobe with the Principled BSDF's (and Metallic BSDF's) anisotropy:
 * a in [0, 1], aspect sqrt(1 - 0.9 a), alpha_x = r^2 / aspect, alpha_y =
 * r^2 aspect, along `tangent`. */
MP_INLINE void mp_add_glossy_aspect(MpSurface* s, float3 w, int slot, float roughness, float anisotropy, float3 tangent,
                                    int fresnel, float3 f0, float3 f82, int multiscatter, float film, float film_ior) {
  float r = clamp(roughness, 0.0f, 1.0f), r2 = r * r;
  float an = clamp(anisotropy, 0.0f, 1.0f), aspect = sqrt(1.0f - 0.9f * an);
  MpClosure c = mp_closure(MP_CLOSURE_GLOSSY, mp_clamp_weight(w), slot, r2 / aspect, r2 * aspect);
  c.tangent = an > 0.0f ? tangent : MP_F3(0.0f, 0.0f, 0.0f);
  c.fresnel = fresnel;
  c.f0 = f0;
  c.f82 = f82;
  c.multiscatter = multiscatter;
#ifdef MP_THIN_FILM
  if (film > MP_THIN_FILM_MIN) {
    c.film = film;
    c.film_ior = fmax(film_ior, 1e-5f);
  }
#endif
  mp_surface_add(s, c);
}

/* Blender 4.x, top to bottom: sheen, coat (with its tint), emission, metal,
 * glass, specular, then subsurface and diffuse. */
MP_INLINE void mp_add_principled_v4(MpSurface* s, float3 w, const MpPrincipled* p, float3 normal) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f), zero = MP_F3(0.0f, 0.0f, 0.0f);
  float metallic = clamp(p->metallic, 0.0f, 1.0f), transmission = clamp(p->transmission, 0.0f, 1.0f);
  float roughness = clamp(p->roughness, 0.0f, 1.0f);
  float3 base = mp_clamp_weight(p->base_color), base1 = mp_min3(base, 1.0f);
  float3 tint = mp_clamp_weight(p->specular_tint);
  float3 tangent = mp_rotate_tangent(p->tangent, normal, p->anisotropic_rotation);
  float sheen = fmax(p->sheen, 0.0f);
#ifdef MP_MICROFIBER_SHEEN
  if (sheen > 1e-5f) {
    float3 sw = sheen * mp_clamp_weight(p->sheen_tint);
    float sr = clamp(p->sheen_roughness, 0.0f, 1.0f);
    mp_add_sheen(s, w * sw, p->slot, sr, MP_SHEEN_MICROFIBER);
    w = w * mp_below(sw * mp_microfiber_sheen_albedo(p->nv, sr));
  }
#endif
  float coat = fmax(p->coat, 0.0f);
  if (coat > 1e-5f) {
    float eta = fmax(p->coat_ior, 1.0f), cr = clamp(p->coat_roughness, 0.0f, 1.0f);
    /* The coat is always energy-preserving. */
    mp_add_glossy(s, w * coat, p->coat_slot, cr, 0.0f, zero, MP_FRESNEL_DIELECTRIC, MP_F3(eta, 0.0f, 0.0f), one, 1);
    float f0 = mp_f0_from_ior(eta);
    w = w * mp_below(coat * mp_layer_albedo(MP_F3(f0, f0, f0), cr, p->coat_nv));
    float3 ct = mp_clamp_weight(p->coat_tint);
    if (!(ct.x == 1.0f && ct.y == 1.0f && ct.z == 1.0f)) {
      /* Along the refracted view's path through the coat. */
      float c = clamp(p->coat_nv, 0.0f, 1.0f);
      float depth = 1.0f / sqrt(fmax(1.0f - (1.0f - c * c) / (eta * eta), 1e-4f));
      float3 t = MP_F3(MP_POWR(ct.x, depth), MP_POWR(ct.y, depth), MP_POWR(ct.z, depth));
      w = w * (one + (t - one) * fmin(coat, 1.0f));
    }
  }
  mp_add_emission(s, w * p->emission);
  if (metallic > 1e-5f)
    mp_add_glossy_aspect(s, w * metallic, p->slot, roughness, p->anisotropy, tangent, MP_FRESNEL_F82, base1,
                         mp_min3(tint, 1.0f), p->multiscatter, p->film_on_metal ? p->thin_film : 0.0f,
                         p->thin_film_ior);
  w = w * (1.0f - metallic);
  float ior = fmax(p->ior, 1e-5f);
  if (transmission > 1e-5f) {
    float3 tw = w * transmission;
    float f0 = mp_f0_from_ior(ior);
    MpClosure c = mp_closure(MP_CLOSURE_GLOSSY, tw, p->slot, roughness * roughness, roughness * roughness);
    c.fresnel = MP_FRESNEL_GENERALIZED;
    c.f0 = mp_min3(tint * f0, 1.0f);
    c.f82 = MP_F3(ior, 0.0f, 0.0f);
    c.multiscatter = p->multiscatter;
    mp_surface_add(s, c);
    /* Light crosses the surface twice: each crossing takes the square root. */
    float3 root = MP_F3(sqrt(base1.x), sqrt(base1.y), sqrt(base1.z));
    mp_add_refraction_tinted(s, tw * root, root, p->slot, roughness, ior, 1);
  }
  w = w * (1.0f - transmission);
  /* The specular layer's IOR moved so its reflectance at normal incidence
   * is scaled by twice the IOR Level. */
  float eta = ior, f0 = mp_f0_from_ior(ior);
  if (p->specular != 0.5f) {
    f0 *= 2.0f * fmax(p->specular, 0.0f);
    eta = mp_ior_from_f0(f0);
    if (ior < 1.0f) eta = 1.0f / eta;
  }
#ifdef MP_THIN_FILM
  int film = p->thin_film > MP_THIN_FILM_MIN;
#else
  int film = 0;
#endif
  if (eta != 1.0f || film) {
    float3 f0c = MP_F3(clamp(f0 * tint.x, 0.0f, 1.0f), clamp(f0 * tint.y, 0.0f, 1.0f), clamp(f0 * tint.z, 0.0f, 1.0f));
    mp_add_glossy_aspect(s, w, p->slot, roughness, p->anisotropy, tangent, MP_FRESNEL_GENERALIZED, f0c,
                         MP_F3(eta, 0.0f, 0.0f), p->multiscatter, p->thin_film, p->thin_film_ior);
    /* A film's layer albedo is its reflectance along the view, as Cycles
     * estimates it (no table spans the film's parameters). */
#ifdef MP_THIN_FILM
    float3 albedo = film ? mp_film_dielectric(clamp(p->nv, 0.0f, 1.0f), p->thin_film, fmax(p->thin_film_ior, 1e-5f), eta, f0c)
                         : mp_layer_albedo(f0c, roughness, p->nv);
#else
    float3 albedo = mp_layer_albedo(f0c, roughness, p->nv);
#endif
    w = w * mp_below(albedo);
  }
  /* The walk enters through the specular layer's IOR and the squared
   * roughness (Skin: its own Subsurface IOR), as in Cycles. */
  float sss = clamp(p->subsurface, 0.0f, 1.0f);
#ifdef MP_SUBSURFACE_WALK
  if (sss > 0.0f)
    mp_add_subsurface_walk(s, w * sss * base1, base1, p->subsurface_radius, p->nv, roughness * roughness,
                           p->subsurface_model == MP_SSS_SKIN ? p->subsurface_ior : eta, p->subsurface_model, p->slot);
#else
  mp_add_subsurface(s, w * sss * base1, p->slot);
#endif
  /* Diffuse Roughness (4.3 and later) is EON's Oren-Nayar of the base colour. */
  mp_add_diffuse_eon(s, w * (1.0f - sss) * base, base, p->slot, p->diffuse_roughness);
}

MP_INLINE void mp_add_principled_v3(MpSurface* s, float3 w, const MpPrincipled* p, float3 normal) {
  float3 one = MP_F3(1.0f, 1.0f, 1.0f), zero = MP_F3(0.0f, 0.0f, 0.0f);
  float metallic = clamp(p->metallic, 0.0f, 1.0f), transmission = clamp(p->transmission, 0.0f, 1.0f);
  float roughness = clamp(p->roughness, 0.0f, 1.0f);
  float3 base = mp_clamp_weight(p->base_color);
  float diffuse_w = (1.0f - metallic) * (1.0f - transmission);
  float transmission_w = (1.0f - metallic) * transmission;
  float sss = clamp(p->subsurface, 0.0f, 1.0f);
  float3 diffuse_color = base * (1.0f - sss) + mp_clamp_weight(p->subsurface_color) * sss;
  MpClosure d = mp_closure(MP_CLOSURE_DIFFUSE, mp_clamp_weight(w * diffuse_color * diffuse_w), p->slot, 0.0f, roughness);
  d.fresnel = p->retro; /* Disney's diffuse with retro-reflection */
  d.f0 = d.weight;
  mp_surface_add(s, d);
  /* Sheen and specular tint by the base colour's hue (specular's by a
   * rougher luminance, as 3.x had it). */
  float lum = mp_luminance(base);
  float3 hue = lum > 0.0f ? base / lum : one;
  if (p->sheen > 0.0f && diffuse_w > 0.0f) {
    float3 sheen_color = one + (hue - one) * p->sheen_tint.x;
    mp_add_sheen(s, w * sheen_color * (p->sheen * diffuse_w), p->slot, 0.0f, MP_SHEEN_PRINCIPLED_V1);
  }
  float3 tangent = mp_rotate_tangent(p->tangent, normal, p->anisotropic_rotation);
  if (p->specular != 0.0f || metallic != 0.0f) {
    float l3 = 0.3f * base.x + 0.6f * base.y + 0.1f * base.z;
    float3 tint = one + ((l3 > 0.0f ? base / l3 : one) - one) * p->specular_tint.x;
    float3 f0 = (p->specular * 0.08f * tint) * (1.0f - metallic) + base * metallic;
    /* 3.x's anisotropy: the aspect sqrt(1 - 0.9 anisotropic). */
    float an = clamp(p->anisotropy, 0.0f, 1.0f), aspect = sqrt(1.0f - 0.9f * an);
    float r2 = roughness * roughness;
    float ax = fmax(r2 / aspect, 1e-4f), ay = fmax(r2 * aspect, 1e-4f);
    MpClosure c = mp_closure(MP_CLOSURE_GLOSSY, w * (1.0f - transmission_w), p->slot, ax, ay);
    c.tangent = an > 0.0f ? tangent : zero;
    c.fresnel = MP_FRESNEL_SCHLICK;
    c.f0 = f0;
    c.multiscatter = p->multiscatter;
    mp_surface_add(s, c);
  }
  if (transmission_w > 0.0f) {
    float tr = 1.0f - (1.0f - roughness) * (1.0f - clamp(p->transmission_roughness, 0.0f, 1.0f));
    mp_add_glossy(s, w * transmission_w, p->slot, roughness, 0.0f, zero, MP_FRESNEL_DIELECTRIC,
                  MP_F3(fmax(p->ior, 1e-5f), 0.0f, 0.0f), one, p->multiscatter);
    mp_add_refraction_tinted(s, w * base * transmission_w, base, p->slot, tr, fmax(p->ior, 1e-5f), 1);
  }
  /* Clearcoat: a quarter-strength coat of IOR 1.5. */
  if (p->coat > 0.0f) {
    float cr = clamp(p->coat_roughness, 0.0f, 1.0f);
    MpClosure c = mp_closure(MP_CLOSURE_CLEARCOAT, mp_clamp_weight(w * (0.25f * p->coat)), p->coat_slot, cr * cr, cr * cr);
    c.fresnel = MP_FRESNEL_DIELECTRIC;
    c.f0 = MP_F3(1.5f, 0.0f, 0.0f);
    c.f82 = one;
    mp_surface_add(s, c);
  }
}

/* Adds Principled BSDF p of weight w; `normal` is its normal slot's
 * direction (anisotropy turns about it). */
MP_INLINE void mp_add_principled(MpSurface* s, float3 w, const MpPrincipled* p, float3 normal) {
  float alpha = clamp(p->alpha, 0.0f, 1.0f);
  if (alpha < 1.0f) {
    mp_add_transparent(s, w * (1.0f - alpha));
    w = w * alpha;
  }
  if (p->v4)
    mp_add_principled_v4(s, w, p, normal);
  else {
    mp_add_emission(s, w * p->emission);
    mp_add_principled_v3(s, w, p, normal);
  }
}

#endif
