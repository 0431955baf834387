/* Hair fibres, as Cycles shades them: the Principled Hair BSDF (the model
 * of Chiang, Bitterli, Tappan and Burley 2016, "A Practical and
 * Controllable Hair and Fur Model for Production Path Tracing", with its
 * roughness remaps and the absorption of its colour parametrisations) and
 * the older Hair BSDF's reflection and transmission lobes. Compiles as
 * OpenCL C and C++ (include mp_compat.h first).
 *
 * A fibre is lit in its own frame: x along the fibre (root to tip), y
 * across it as seen from the viewer, z the rest. A grid vertex of a hair
 * tube (scene/curves.h) sits at offset h = sin(gamma_o) across the fibre's
 * width, read from its normal; Cycles reads the same h where its ray hits
 * the curve, so a tube diced a few micropolygons across (MP_PATCH_ROUND_U)
 * averages the lobes over the width as Cycles' pixels do.
 *
 * Closure fields (MpClosure):
 *   MP_CLOSURE_HAIR: f0 = absorption sigma_a; a, b = longitudinal and
 *     azimuthal roughness (the node's, 0..1); f82 = (coat's primary
 *     roughness factor 1 - coat, IOR, cuticle tilt in radians);
 *     tangent = the fibre's direction.
 *   MP_CLOSURE_HAIR_REFLECTION / _TRANSMISSION: a, b = roughness along and
 *     around the fibre; f82.x = the angular offset (the node's, negated as
 *     Cycles stores it); tangent likewise.
 *   Both: film = the fibre's radius in camera space (0: unknown). A fibre
 *   does not shadow the light it transmits (Cycles' shadow rays skip their
 *   own curve), so lamps light it as seen from just outside it towards the
 *   lamp (mp_shade_closures). */
#ifndef MP_HAIR_H
#define MP_HAIR_H

#include "core/mp_compat.h"
#include "closures/mp_bsdf.h"
#include "closures/mp_closures.h"

#define MP_HAIR_PI 3.14159265f

/* Whether a closure kind is one of the hair lobes, which take light from
 * every side of the fibre (no hemisphere about the surface normal). */
MP_INLINE int mp_closure_is_hair(int kind) {
  return kind == MP_CLOSURE_HAIR || kind == MP_CLOSURE_HAIR_REFLECTION || kind == MP_CLOSURE_HAIR_TRANSMISSION;
}

/* ---- colour parametrisations (absorption per unit fibre radius) ---- */

/* The divisor that turns log(colour) into sqrt(sigma_a) for a radial
 * roughness (Chiang et al. 2016, eq. 9). */
MP_INLINE float mp_hair_colour_scale(float radial) {
  float x = radial;
  return (((((0.245f * x) + 5.574f) * x - 10.73f) * x + 2.532f) * x - 0.215f) * x + 5.969f;
}

/* Absorption that gives a hair volume the colour `c` (Direct Coloring). */
MP_INLINE float3 mp_hair_sigma_from_colour(float3 c, float radial) {
  float k = 1.0f / mp_hair_colour_scale(radial);
  float3 s = MP_F3(log(fmax(c.x, 1e-4f)), log(fmax(c.y, 1e-4f)), log(fmax(c.z, 1e-4f))) * k;
  return s * s;
}

/* Absorption of a melanin concentration (Melanin Concentration): the
 * node's 0..1 amount maps to -log(1 - amount) and splits into eu- and
 * pheomelanin by the redness, each with its absorption spectrum (Cycles'
 * values in every Blender from 3.4 on); a Tint adds its colour's. */
MP_INLINE float3 mp_hair_sigma_from_melanin(float melanin, float redness, float3 tint, float radial) {
  float m = -log(fmax(1.0f - melanin, 0.0001f));
  float eu = m * (1.0f - redness), pheo = m * redness;
  return eu * MP_F3(0.506f, 0.841f, 1.653f) + pheo * MP_F3(0.343f, 0.733f, 1.924f) +
         mp_hair_sigma_from_colour(tint, radial);
}

/* The colour a parametrisation's absorption stands for (the inverse of
 * mp_hair_sigma_from_colour): the fibre's albedo under the world's light. */
MP_INLINE float3 mp_hair_albedo(const MpClosure* c) {
  float k = mp_hair_colour_scale(c->b);
  return MP_F3(exp(-sqrt(fmax(c->f0.x, 0.0f)) * k), exp(-sqrt(fmax(c->f0.y, 0.0f)) * k),
               exp(-sqrt(fmax(c->f0.z, 0.0f)) * k));
}

/* ---- closures ---- */

MP_INLINE void mp_add_principled_hair(MpSurface* s, float3 w, int slot, float3 sigma, float roughness,
                                      float radial, float coat, float ior, float offset, float3 fibre,
                                      float radius) {
  MpClosure c = mp_closure(MP_CLOSURE_HAIR, mp_clamp_weight(w), slot, fmin(fmax(roughness, 0.001f), 1.0f),
                           fmin(fmax(radial, 0.001f), 1.0f));
  c.f0 = MP_F3(fmax(sigma.x, 0.0f), fmax(sigma.y, 0.0f), fmax(sigma.z, 0.0f));
  c.f82 = MP_F3(1.0f - fmin(fmax(coat, 0.0f), 1.0f), fmax(ior, 1.0001f), offset);
  c.tangent = fibre;
  c.film = radius;
  mp_surface_add(s, c);
}

/* Cycles' Hair BSDF: `transmission` picks the component. */
MP_INLINE void mp_add_hair(MpSurface* s, float3 w, int slot, int transmission, float offset, float roughness_u,
                           float roughness_v, float3 fibre, float radius) {
  MpClosure c = mp_closure(transmission ? MP_CLOSURE_HAIR_TRANSMISSION : MP_CLOSURE_HAIR_REFLECTION,
                           mp_clamp_weight(w), slot, fmin(fmax(roughness_u, 0.001f), 1.0f),
                           fmin(fmax(roughness_v, 0.001f), 1.0f));
  c.f82 = MP_F3(-offset, 0.0f, 0.0f);
  c.tangent = fibre;
  c.film = radius;
  mp_surface_add(s, c);
}

/* ---- Chiang et al.'s lobes ---- */

/* Roughness -> the longitudinal lobes' variance v (section 4.1). */
MP_INLINE float mp_hair_variance(float beta) {
  float b2 = beta * beta, b4 = b2 * b2, b8 = b4 * b4, b16 = b8 * b8;
  float x = 0.726f * beta + 0.812f * b2 + 3.7f * (b16 * b4);
  return x * x;
}

/* Radial roughness -> the azimuthal logistic's scale s (sqrt(pi / 8) times
 * the fitted polynomial). */
MP_INLINE float mp_hair_logistic_scale(float beta) {
  float b2 = beta * beta, b4 = b2 * b2, b8 = b4 * b4, b16 = b8 * b8;
  return (0.265f * beta + 1.194f * b2 + 5.372f * (b16 * b4 * b2)) * 0.62665707f;
}

/* The modified Bessel function I0 by its power series to the (x/2)^18
 * term, as Cycles sums it (which is what its lobes are normalised with),
 * and its logarithm (asymptotic past 12). */
MP_INLINE float mp_hair_bessel_i0(float x) {
  float q = 0.25f * x * x, term = 1.0f, sum = 1.0f;
  for (int i = 1; i < 10; ++i) {
    term *= q / (float)(i * i);
    sum += term;
  }
  return sum;
}
MP_INLINE float mp_hair_log_i0(float x) {
  if (x > 12.0f) return x + 0.5f * (1.0f / (8.0f * x) - 1.83787707f - log(x)); /* log(2 pi) */
  return log(mp_hair_bessel_i0(x));
}

/* Longitudinal scattering M_p of variance v (d'Eon et al. 2011's
 * normalised form; in logarithms for narrow lobes). */
MP_INLINE float mp_hair_longitudinal(float sin_i, float cos_i, float sin_o, float cos_o, float v) {
  float inv = 1.0f / v, a = cos_i * cos_o * inv, b = sin_i * sin_o * inv;
  if (v <= 0.1f) return exp(mp_hair_log_i0(a) - b - inv + 0.6931f + log(0.5f * inv));
  return exp(-b) * mp_hair_bessel_i0(a) / (sinh(inv) * 2.0f * v);
}

/* Azimuthal scattering N_p: a logistic of scale s, trimmed to [-pi, pi],
 * about the lobe's exit angle. */
MP_INLINE float mp_hair_azimuthal(float phi, int p, float s, float gamma_o, float gamma_t) {
  float d = phi - (2.0f * (float)p * gamma_t - 2.0f * gamma_o + (float)p * MP_HAIR_PI);
  d = d + MP_HAIR_PI - 2.0f * MP_HAIR_PI * floor((d + MP_HAIR_PI) / (2.0f * MP_HAIR_PI)) - MP_HAIR_PI;
  float e = exp(-fabs(d) / s);
  float trim = 1.0f - 2.0f / (1.0f + exp(MP_HAIR_PI / s));
  return trim > 0.0f ? e / (s * (1.0f + e) * (1.0f + e)) / trim : 0.0f;
}

/* The fibre frame of tangent t seen from v: x, y, z as above; false where
 * the fibre points at the viewer. */
MP_INLINE int mp_hair_frame(float3 t, float3 v, float3* x, float3* y, float3* z) {
  float lt = length(t);
  if (!(lt > 0.0f)) return 0;
  *x = t / lt;
  float3 c = cross(*x, v);
  float lc = length(c);
  if (!(lc > 1e-6f)) return 0;
  *y = c / lc;
  *z = cross(*x, *y);
  return 1;
}

/* What Chiang's lobes take from the view alone: the fibre frame, the
 * vertex's offset h across the fibre, the angles of the refracted path and
 * the attenuations A_p of R, TT, TRT and the rest. Computed once per vertex
 * and read for every direction light arrives from (an area light's 16
 * points), where only the longitudinal and azimuthal terms change. */
typedef struct {
  float3 x, y, z;
  float sin_o, cos_o, phi_o, gamma_o, gamma_t;
  float v_lobe, v_r, s;
  float s1, c1, s2, c2, s4, c4; /* the cuticle's tilt: sin and cos of alpha, 2 alpha, 4 alpha */
  float3 a0, a1, a2, a3;
  int ok;
} MpHairView;

/* The view's part of Principled Hair (Chiang) towards v; n: the surface
 * normal at the vertex, which places it across the fibre. */
MP_INLINE MpHairView mp_hair_chiang_view(const MpClosure* c, float3 n, float3 v) {
  MpHairView w;
  w.ok = mp_hair_frame(c->tangent, v, &w.x, &w.y, &w.z);
  if (!w.ok) return w;
  float eta = c->f82.y, alpha = c->f82.z;
  w.v_lobe = mp_hair_variance(c->a);
  w.s = mp_hair_logistic_scale(c->b);
  w.v_r = mp_hair_variance(fmin(fmax(c->f82.x * c->a, 0.001f), 1.0f));
  float h = fmin(fmax(dot(cross(n, w.x), w.z), -1.0f), 1.0f);

  w.sin_o = dot(v, w.x);
  w.cos_o = sqrt(fmax(1.0f - w.sin_o * w.sin_o, 0.0f));
  w.phi_o = atan2(dot(v, w.z), dot(v, w.y));
  float sin_t = w.sin_o / eta, cos_t = sqrt(fmax(1.0f - sin_t * sin_t, 0.0f));
  float cos_gamma_o = sqrt(fmax(1.0f - h * h, 0.0f));
  w.gamma_o = asin(h);
  float sin_gamma_t = h * w.cos_o / sqrt(fmax(eta * eta - w.sin_o * w.sin_o, 1e-12f));
  sin_gamma_t = fmin(fmax(sin_gamma_t, -1.0f), 1.0f);
  float cos_gamma_t = sqrt(fmax(1.0f - sin_gamma_t * sin_gamma_t, 0.0f));
  w.gamma_t = asin(sin_gamma_t);
  float3 sigma = c->f0 * (2.0f * cos_gamma_t / fmax(cos_t, 1e-6f));
  float3 tr = MP_F3(exp(-sigma.x), exp(-sigma.y), exp(-sigma.z));
  /* Attenuation of R, TT, TRT and the rest (a geometric series). */
  float f = mp_fresnel_dielectric(w.cos_o * cos_gamma_o, eta);
  w.a0 = MP_F3(f, f, f);
  w.a1 = (1.0f - f) * (1.0f - f) * tr;
  w.a2 = w.a1 * tr * f;
  float3 tf = tr * f;
  w.a3 = w.a2 * MP_F3(tf.x / fmax(1.0f - tf.x, 1e-6f), tf.y / fmax(1.0f - tf.y, 1e-6f),
                      tf.z / fmax(1.0f - tf.z, 1e-6f));
  /* The cuticle's scales tilt each lobe by -2, 1 and 4 times alpha. */
  w.s1 = sin(alpha);
  w.c1 = sqrt(fmax(1.0f - w.s1 * w.s1, 0.0f));
  w.s2 = 2.0f * w.s1 * w.c1;
  w.c2 = w.c1 * w.c1 - w.s1 * w.s1;
  w.s4 = 2.0f * w.s2 * w.c2;
  w.c4 = w.c2 * w.c2 - w.s2 * w.s2;
  return w;
}

/* Principled Hair (Chiang) of view `w` from light direction l, per unit
 * radiance arriving from l over unit solid angle (the lobes integrate to
 * the fibre's albedo; no cosine, as light reaches a fibre from any side). */
MP_INLINE float3 mp_hair_chiang_from(const MpHairView* w, float3 l) {
  if (!w->ok) return MP_F3(0.0f, 0.0f, 0.0f);
  float sin_i = dot(l, w->x), cos_i = sqrt(fmax(1.0f - sin_i * sin_i, 0.0f));
  float phi = atan2(dot(l, w->z), dot(l, w->y)) - w->phi_o;
  float sin_r = sin_i * w->c2 + cos_i * w->s2, cos_r = fabs(cos_i * w->c2 - sin_i * w->s2);
  float sin_tt = sin_i * w->c1 - cos_i * w->s1, cos_tt = fabs(cos_i * w->c1 + sin_i * w->s1);
  float sin_trt = sin_i * w->c4 - cos_i * w->s4, cos_trt = fabs(cos_i * w->c4 + sin_i * w->s4);

  float3 out = w->a0 * (mp_hair_longitudinal(sin_r, cos_r, w->sin_o, w->cos_o, w->v_r) *
                        mp_hair_azimuthal(phi, 0, w->s, w->gamma_o, w->gamma_t));
  out += w->a1 * (mp_hair_longitudinal(sin_tt, cos_tt, w->sin_o, w->cos_o, 0.25f * w->v_lobe) *
                  mp_hair_azimuthal(phi, 1, w->s, w->gamma_o, w->gamma_t));
  out += w->a2 * (mp_hair_longitudinal(sin_trt, cos_trt, w->sin_o, w->cos_o, 4.0f * w->v_lobe) *
                  mp_hair_azimuthal(phi, 2, w->s, w->gamma_o, w->gamma_t));
  out += w->a3 * (mp_hair_longitudinal(sin_i, cos_i, w->sin_o, w->cos_o, 4.0f * w->v_lobe) * (0.5f / MP_HAIR_PI));
  return out;
}

/* Principled Hair (Chiang) towards v from light direction l. */
MP_INLINE float3 mp_hair_chiang(const MpClosure* c, float3 n, float3 l, float3 v) {
  MpHairView w = mp_hair_chiang_view(c, n, v);
  return mp_hair_chiang_from(&w, l);
}

/* Cycles' Hair BSDF lobes towards v from l (the same measure as
 * mp_hair_chiang): a Cauchy-like longitudinal lobe about the half angle
 * shifted by the offset, and an azimuthal cosine (reflection, on the
 * viewer's side of the fibre) or Cauchy lobe about the far side
 * (transmission). The surface's side decides which may light it, as
 * Cycles' reflect and transmit evaluations do with the geometric normal. */
MP_INLINE float mp_hair_kajiya(const MpClosure* c, float3 n, float3 l, float3 v) {
  float lt = length(c->tangent);
  if (!(lt > 0.0f)) return 0.0f;
  float3 t = c->tangent / lt;
  int transmission = c->kind == MP_CLOSURE_HAIR_TRANSMISSION;
  if ((dot(n, l) >= 0.0f) == transmission) return 0.0f;
  float r1 = c->a, r2 = c->b, offset = c->f82.x;
  float vz = fmin(fmax(dot(t, v), -1.0f), 1.0f), lz = fmin(fmax(dot(t, l), -1.0f), 1.0f);
  float3 vy = v - t * vz, ly = l - t * lz;
  if (!(length(vy) > 0.0f) || !(length(ly) > 0.0f)) return 0.0f;
  vy = normalize(vy);
  ly = normalize(ly);
  float theta_r = asin(vz), theta_i = asin(lz);
  if (0.5f * MP_HAIR_PI - fabs(theta_i) < 0.001f) return 0.0f;
  float cos_phi = fmin(fmax(dot(ly, vy), -1.0f), 1.0f);
  float a = atan(((0.5f * MP_HAIR_PI + theta_r) * 0.5f - offset) / r1);
  float b = atan(((-0.5f * MP_HAIR_PI + theta_r) * 0.5f - offset) / r1);
  float th = 0.5f * (theta_i + theta_r) - offset;
  float theta_pdf = r1 / (2.0f * (th * th + r1 * r1) * (a - b) * cos(theta_i));
  if (!transmission) {
    if (cos_phi < 0.0f) return 0.0f;
    float phi_i = fmin(acos(cos_phi) / r2, MP_HAIR_PI);
    return cos(0.5f * phi_i) * 0.25f / r2 * theta_pdf;
  }
  float p = MP_HAIR_PI - acos(cos_phi);
  float c_tt = 2.0f * atan(0.5f * MP_HAIR_PI / r2);
  return r2 / (c_tt * (p * p + r2 * r2)) * theta_pdf;
}

#endif
