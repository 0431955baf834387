/* Thin-film interference on a specular layer: the Principled BSDF's Thin
 * Film (Blender 4.2 and later), a film of thickness d (nanometres) and IOR
 * n_f between the air and the dielectric or metal below.
 *
 * Light reflected at the film's top and light that crossed it and came back
 * differ in phase by the optical path difference 2 n_f d cos(theta_f); per
 * wavelength, the Airy sum over all orders of internal reflection gives the
 * film's reflectance. Summing that against the colour matching functions
 * at every wavelength would take dozens of evaluations; Belcour and Barla
 * (2017, "A Practical Extension to Microfacet Theory for the Modeling of
 * Varying Iridescence", eq. 10) write the sum over path orders m instead,
 * each order weighted by the sensitivity's Fourier transform at m times the
 * path difference (mp_thin_film_table.h). Orders past 3 add too little to
 * keep, as in Cycles, whose table and truncation these follow so a film
 * shows the same colours in both. Compiles as OpenCL C and C++. */
#ifndef MP_THIN_FILM_H
#define MP_THIN_FILM_H

#include "core/mp_compat.h"
#include "closures/mp_bsdf.h"
#include "tables/mp_thin_film_table.h"

/* Films thinner than this (nm) leave the Fresnel term as it is (Cycles'
 * cutoff); below 1 nm the film's IOR fades towards the air's. */
#define MP_THIN_FILM_MIN 0.1f

/* The sensitivity spectrum of channel c (0 r, 1 g, 2 b) at optical path
 * difference opd (nm): (real, imaginary), linear between the table's bins. */
MP_INLINE float2 mp_film_sensitivity(int c, float opd) {
  float x = clamp(2.0f * MP_BSDF_PI * opd / 60000.0f, 0.0f, 1.0f) * (float)(MP_THIN_FILM_BINS - 1);
  int i = (int)fmin(floor(x), (float)(MP_THIN_FILM_BINS - 2));
  float t = x - (float)i;
  int a = 6 * i + c, b = a + 6;
  return MP_F2(mp_thin_film_table[a] + (mp_thin_film_table[b] - mp_thin_film_table[a]) * t,
               mp_thin_film_table[a + 3] + (mp_thin_film_table[b + 3] - mp_thin_film_table[a + 3]) * t);
}

/* Reflectance of the s and p waves at a dielectric interface (relative IOR
 * eta = n_below / n_above, cos_i > 0 on the incident side), the sign of
 * each reflected amplitude (+1 or -1: a phase shift of 0 or pi) and the
 * cosine of the transmitted direction. Returns 0 on total internal
 * reflection (then R = 1). */
MP_INLINE int mp_fresnel_polarized(float cos_i, float eta, float2* r, float2* sign, float* cos_t) {
  float c = fabs(cos_i), t2 = eta * eta - (1.0f - c * c);
  if (!(t2 > 0.0f)) {
    *r = MP_F2(1.0f, 1.0f);
    *sign = MP_F2(1.0f, 1.0f);
    *cos_t = 0.0f;
    return 0;
  }
  float t = sqrt(t2) / eta;
  float rs = (c - eta * t) / (c + eta * t), rp = (eta * c - t) / (eta * c + t);
  *r = MP_F2(rs * rs, rp * rp);
  *sign = MP_F2(rs >= 0.0f ? 1.0f : -1.0f, rp >= 0.0f ? 1.0f : -1.0f);
  *cos_t = t;
  return 1;
}

/* Reflectance of the s and p waves from a medium of IOR n1 onto a
 * conductor of IOR n + ik (Born and Wolf, Principles of Optics, 14.4.1,
 * with n + ik for the complex index), and the phase of each reflected
 * amplitude as a unit complex number (re, im). The reflectance follows the
 * F82 model of the metal's own colour (f82 >= 0, both polarisations alike),
 * so a film over a metal keeps the metal's colour where the film is thin. */
MP_INLINE void mp_conductor_polarized(float cos_i, float n1, float n, float k, float f82, float2* r, float2* phase_s,
                                      float2* phase_p) {
  float n1_2 = n1 * n1, n2 = n * n, k2 = k * k, nk2 = 2.0f * n * k;
  float t1 = n2 - k2 - n1_2 * (1.0f - cos_i * cos_i);
  float t2 = sqrt(t1 * t1 + nk2 * nk2);
  float u2 = fmax(0.5f * (t2 + t1), 0.0f), v2 = fmax(0.5f * (t2 - t1), 0.0f), u = sqrt(u2), v = sqrt(v2);
  float rn = n / n1, rk2 = k2 / n1_2;
  float f0 = ((rn - 1.0f) * (rn - 1.0f) + rk2) / ((rn + 1.0f) * (rn + 1.0f) + rk2);
  float rf = mp_f82(cos_i, f0, mp_f82_b(f0, f82));
  *r = MP_F2(rf, rf);
  float re_s = n1_2 * cos_i * cos_i - u2 - v2, im_s = -2.0f * n1 * cos_i * v;
  float mag_s = sqrt(re_s * re_s + im_s * im_s);
  *phase_s = mag_s > 0.0f ? MP_F2(re_s / mag_s, im_s / mag_s) : MP_F2(1.0f, 0.0f);
  float a = (n2 + k2) * cos_i;
  float re_p = a * a - n1_2 * (u2 + v2), im_p = 2.0f * n1 * cos_i * (nk2 * u - (n2 - k2) * v);
  float mag_p = sqrt(re_p * re_p + im_p * im_p);
  *phase_p = mag_p > 0.0f ? MP_F2(re_p / mag_p, im_p / mag_p) : MP_F2(1.0f, 0.0f);
}

/* The Airy sum of one polarisation for channel c: reflectances r12 (top)
 * and r23 (bottom), the path difference opd and the phase (a unit complex
 * number) a round trip adds besides it. */
MP_INLINE float mp_film_airy(int c, float r12, float r23, float opd, float2 phase) {
  float t121 = 1.0f - r12, r123 = r12 * r23, root = sqrt(r123);
  float rs = t121 * t121 * r23 / (1.0f - r123);
  float sum = r12 + rs, cm = rs - t121;
  float2 z = phase;
  for (int m = 1; m <= 3; ++m) {
    cm *= root;
    float2 s = mp_film_sensitivity(c, (float)m * opd);
    sum += 2.0f * cm * (z.x * s.x + z.y * s.y);
    z = MP_F2(z.x * phase.x - z.y * phase.y, z.x * phase.y + z.y * phase.x);
  }
  return sum;
}

/* The film's reflectance in channel c at incidence cos_i from the air
 * (IOR 1), over a dielectric of IOR `below` (conductor 0) or a conductor
 * n + ik whose F82 reflectance is f82. */
MP_INLINE float mp_film_channel(int c, float cos_i, float thickness, float film_ior, float below, float n, float k,
                                float f82, int conductor) {
  float nf = film_ior;
  if (thickness < 1.0f) {
    float t = clamp(thickness, 0.0f, 1.0f);
    nf = 1.0f + (film_ior - 1.0f) * t * t * (3.0f - 2.0f * t);
  }
  float2 r12, s12;
  float cos_f;
  if (!mp_fresnel_polarized(cos_i, nf, &r12, &s12, &cos_f)) return 1.0f;
  float2 r23, ph_s, ph_p;
  if (conductor) {
    mp_conductor_polarized(cos_f, nf, n, k, f82, &r23, &ph_s, &ph_p);
  } else {
    float2 s23;
    float cos_b;
    if (!mp_fresnel_polarized(cos_f, below / nf, &r23, &s23, &cos_b)) return 1.0f;
    ph_s = MP_F2(s23.x, 0.0f);
    ph_p = MP_F2(s23.y, 0.0f);
  }
  float opd = 2.0f * nf * thickness * cos_f;
  /* The top reflection seen from inside the film flips the sign of its amplitude. */
  float rs = mp_film_airy(c, r12.x, r23.x, opd, ph_s * -s12.x);
  float rp = mp_film_airy(c, r12.y, r23.y, opd, ph_p * -s12.y);
  return clamp(0.5f * (rs + rp), 0.0f, 1.0f);
}

/* A film over the Principled BSDF's dielectric specular layer: the film's
 * reflectance over a dielectric of IOR `ior`, scaled towards f0 / F0(ior)
 * (the layer's IOR Level and Specular Tint) as far as it lies from 1 toward
 * the dielectric's own F0, as Cycles scales it. */
MP_INLINE float3 mp_film_dielectric(float cos_i, float thickness, float film_ior, float ior, float3 f0) {
  float f[3];
  float f0_real = mp_f0_from_ior(ior);
  float3 one = MP_F3(1.0f, 1.0f, 1.0f);
  for (int c = 0; c < 3; ++c) f[c] = mp_film_channel(c, cos_i, thickness, film_ior, ior, 0.0f, 0.0f, 0.0f, 0);
  float3 r = MP_F3(f[0], f[1], f[2]);
  if (f0_real > 1e-5f && !(f[0] == 1.0f && f[1] == 1.0f && f[2] == 1.0f)) {
    float3 factor = f0 / f0_real, s;
    for (int c = 0; c < 3; ++c) f[c] = clamp((f[c] - 1.0f) / (f0_real - 1.0f), 0.0f, 1.0f);
    s = MP_F3(f[0], f[1], f[2]);
    r = r * (one + (factor - one) * s);
  }
  return r;
}

/* A film over the Principled BSDF's metal: its F0 (Base Color) and F82
 * tint read as a conductor's n and k (Gulbrandsen 2014, "Artist Friendly
 * Metallic Fresnel", r = F0 and g = the reflectance at 82 degrees). */
MP_INLINE float3 mp_film_metal(float cos_i, float thickness, float film_ior, float3 f0, float3 tint) {
  float f[3], f0c[3] = {f0.x, f0.y, f0.z}, tc[3] = {tint.x, tint.y, tint.z};
  for (int c = 0; c < 3; ++c) {
    float r = fmin(f0c[c], 0.999f), sr = sqrt(r);
    float g = mp_f82(1.0f / 7.0f, f0c[c], mp_f82_tint_b(f0c[c], tc[c]));
    float n = (1.0f + sr) / (1.0f - sr) + ((1.0f - r) / (1.0f + r) - (1.0f + sr) / (1.0f - sr)) * g;
    float k = sqrt(fmax((r * (n + 1.0f) * (n + 1.0f) - (n - 1.0f) * (n - 1.0f)) / (1.0f - r), 0.0f));
    f[c] = mp_film_channel(c, cos_i, thickness, film_ior, 0.0f, n, k, g, 1);
  }
  return MP_F3(f[0], f[1], f[2]);
}

#endif
