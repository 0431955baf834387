/* The BSDFs closures evaluate (mp_closures.h), as Cycles defines them,
 * each as f(l, v) times the cosine it receives light at. Vectors are unit,
 * in one space, n on the viewer's side. Compiles as OpenCL C and C++. */
#ifndef MP_BSDF_H
#define MP_BSDF_H

#include "core/mp_compat.h"
#include "tables/mp_ggx_albedo.h"
/* Microfiber sheen's table (mp_sheen_ltc_table.h) only where a sheen can
 * be: the host and material programs. The main program's constant
 * materials have none, and a large constant table in its shade kernel
 * costs it 8% on an H100 even unread. */
#if !defined(__OPENCL_VERSION__) || defined(MP_MATERIAL_PROGRAM)
#define MP_MICROFIBER_SHEEN 1
#include "tables/mp_sheen_ltc_table.h"
#endif

#define MP_BSDF_PI 3.14159265358979f

/* Fresnel reflectance of a dielectric interface of relative IOR eta for
 * the cosine c between the incident direction and the normal (1 under
 * total internal reflection). */
MP_INLINE float mp_fresnel_dielectric(float c, float eta) {
  c = fabs(c);
  float g = eta * eta - 1.0f + c * c;
  if (!(g > 0.0f)) return 1.0f;
  g = sqrt(g);
  float a = (g - c) / (g + c), b = (c * (g + c) - 1.0f) / (c * (g - c) + 1.0f);
  return 0.5f * a * a * (1.0f + b * b);
}

MP_INLINE float mp_schlick_weight(float c) {
  float t = clamp(1.0f - c, 0.0f, 1.0f), t2 = t * t;
  return t2 * t2 * t;
}

/* Hoffman's F82 model for metals, one channel: Schlick's curve from f0 less
 * b mu (1 - mu)^6, a dip that peaks near 82 degrees (mu = 1/7). mp_f82_b:
 * the b that takes the curve through f82 at mu = 1/7; mp_f82_tint_b: the b
 * of the F82-tint form, Schlick's value there times tint (Cycles' metal). */
MP_INLINE float mp_f82(float mu, float f0, float b) {
  float s = clamp(1.0f - mu, 0.0f, 1.0f), s5 = s * s * s * s * s;
  return clamp(f0 + (1.0f - f0) * s5 - b * mu * s5 * s, 0.0f, 1.0f);
}
MP_INLINE float mp_f82_b(float f0, float f82) {
  const float q = 6.0f / 7.0f;
  float q5 = q * q * q * q * q;
  return (7.0f / (q5 * q)) * (f0 + (1.0f - f0) * q5 - f82);
}
MP_INLINE float mp_f82_tint_b(float f0, float tint) {
  const float q = 6.0f / 7.0f;
  return mp_f82_b(f0, (f0 + (1.0f - f0) * q * q * q * q * q) * tint);
}

/* F0 of a dielectric of IOR eta. */
MP_INLINE float mp_f0_from_ior(float eta) {
  float r = (eta - 1.0f) / (eta + 1.0f);
  return r * r;
}
MP_INLINE float mp_ior_from_f0(float f0) {
  float s = sqrt(clamp(f0, 0.0f, 0.99f));
  return (1.0f + s) / (1.0f - s);
}

/* GGX's Smith Lambda for direction w of local coordinates (x, y, z). */
MP_INLINE float mp_ggx_lambda(float3 w, float ax, float ay) {
  float z2 = w.z * w.z;
  if (!(z2 > 0.0f)) return 1e10f;
  float t2 = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2;
  return 0.5f * (sqrt(1.0f + t2) - 1.0f);
}

/* Anisotropic GGX distribution at local half vector h. */
MP_INLINE float mp_ggx_d(float3 h, float ax, float ay) {
  float x = h.x / ax, y = h.y / ay, k = x * x + y * y + h.z * h.z;
  return 1.0f / (MP_BSDF_PI * ax * ay * k * k);
}

/* The local frame of normal n with tangent t (t may be zero). */
MP_INLINE void mp_frame(float3 n, float3 t, float3* x, float3* y) {
  float3 tx = t - dot(t, n) * n;
  float len = length(tx);
  if (!(len > 1e-6f)) {
    float3 a = fabs(n.x) < 0.9f ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f);
    tx = normalize(cross(a, n));
  } else
    tx = tx / len;
  *x = tx;
  *y = cross(n, tx);
}

/* GGX reflection D G / (4 nl nv) with the height-correlated Smith term,
 * without Fresnel; 0 unless both directions are above the surface. */
MP_INLINE float mp_ggx_reflect(float3 n, float3 tx, float3 ty, float3 l, float3 v, float ax, float ay) {
  ax = fmax(ax, 1e-4f), ay = fmax(ay, 1e-4f);
  float3 h = normalize(l + v);
  float3 hl = MP_F3(dot(h, tx), dot(h, ty), dot(h, n));
  if (!(hl.z > 0.0f)) return 0.0f;
  float3 ll = MP_F3(dot(l, tx), dot(l, ty), dot(l, n)), vl = MP_F3(dot(v, tx), dot(v, ty), dot(v, n));
  if (!(vl.z > 0.0f && ll.z > 0.0f)) return 0.0f;
  float g = 1.0f / (1.0f + mp_ggx_lambda(ll, ax, ay) + mp_ggx_lambda(vl, ax, ay));
  return mp_ggx_d(hl, ax, ay) * g / (4.0f * ll.z * vl.z);
}

/* Principled 3.x's clearcoat (Burley 2012): the GTR1 distribution of
 * alpha a, Smith shadowing of a GGX of fixed alpha 0.25 taken separately
 * for view and light, and the Fresnel term of IOR 1.5; f. */
MP_INLINE float mp_clearcoat(float3 n, float3 l, float3 v, float a) {
  float nl = dot(n, l), nv = dot(n, v);
  if (!(nl > 0.0f && nv > 0.0f)) return 0.0f;
  float3 h = normalize(l + v);
  float nh = dot(n, h), a2 = fmax(a * a, 1e-7f);
  float d = a2 >= 1.0f ? 1.0f / MP_BSDF_PI : (a2 - 1.0f) / (MP_BSDF_PI * log(a2) * (1.0f + (a2 - 1.0f) * nh * nh));
  const float g2 = 0.0625f;
  float gl = 2.0f / (1.0f + sqrt(1.0f + g2 * (1.0f / (nl * nl) - 1.0f)));
  float gv = 2.0f / (1.0f + sqrt(1.0f + g2 * (1.0f / (nv * nv) - 1.0f)));
  return d * gl * gv * mp_fresnel_dielectric(dot(l, h), 1.5f) / (4.0f * nl * nv);
}

/* Oren-Nayar as Cycles' Diffuse BSDF with roughness sigma (the
 * "qualitative" model of Fujii): f cos = nl (A + B s) with
 * s = max(0, l.v - nl nv) / max(nl, nv), A = 1 / (pi + (pi/2 - 2/3) sigma),
 * B = sigma A. */
MP_INLINE float mp_oren_nayar(float3 n, float3 l, float3 v, float sigma) {
  float nl = fmax(dot(n, l), 0.0f), nv = fmax(dot(n, v), 0.0f);
  float t = dot(l, v) - nl * nv;
  if (t > 0.0f) t /= fmax(nl, nv) + 1e-20f;
  float a = 1.0f / (MP_BSDF_PI + (0.5f * MP_BSDF_PI - 2.0f / 3.0f) * sigma);
  return nl * (a + sigma * a * t);
}

/* Oren-Nayar's directional albedo for white light from every direction:
 * the integral of (A + B s) cos over the hemisphere is A (pi + sigma G(c)),
 * c the cosine to the normal, with G from Fujii's derivation (OpenPBR's
 * energy-preserving Oren-Nayar, "EON": Portsmouth et al. 2024). Below
 * c = 1e-6 tan explodes; G's value at grazing is its first-order series. */
MP_INLINE float mp_oren_nayar_g(float c) {
  if (!(c >= 1e-6f)) return (0.5f * MP_BSDF_PI - 2.0f / 3.0f) - fmax(c, 0.0f);
  float s = sqrt(fmax(1.0f - c * c, 0.0f)), theta = acos(fmin(c, 1.0f));
  return s * (theta - 2.0f / 3.0f - s * c) + (2.0f / 3.0f) * (s / c) * (1.0f - s * s * s);
}
MP_INLINE float mp_oren_nayar_albedo(float c, float sigma) {
  float a = 1.0f / (MP_BSDF_PI + (0.5f * MP_BSDF_PI - 2.0f / 3.0f) * sigma);
  return a * (MP_BSDF_PI + sigma * mp_oren_nayar_g(c));
}
/* Its cosine-weighted average over directions (EON: A + (2/3 - 28/(15 pi)) B
 * in OpenPBR's normalisation). */
MP_INLINE float mp_oren_nayar_average(float sigma) {
  float a = 1.0f / (MP_BSDF_PI + (0.5f * MP_BSDF_PI - 2.0f / 3.0f) * sigma);
  return a * (MP_BSDF_PI + (2.0f * MP_BSDF_PI / 3.0f - 28.0f / 15.0f) * sigma);
}
/* EON's multiple-scattering lobe, per unit irradiance, for albedo rho
 * (clamped to [0, 1]): rho_ms / pi (1 - E(nl)) (1 - E(nv)) / (1 - Eavg) with
 * rho_ms = rho^2 Eavg / (1 - rho (1 - Eavg)), which gives back what the
 * single-scattering lobe loses (a white surface reflects all it receives).
 * Cycles 4.3 and later multiply the closure's weight (the colour) on top,
 * and so does mp_shade_closures. */
MP_INLINE float mp_eon_ms_scale(float rho, float eavg) {
  if (!(eavg < 1.0f)) return 0.0f; /* no roughness, nothing lost */
  rho = clamp(rho, 0.0f, 1.0f);
  return rho * rho * eavg / ((1.0f - eavg) * (1.0f - rho * (1.0f - eavg))) * (1.0f / MP_BSDF_PI);
}
MP_INLINE float3 mp_eon_ms(float3 rho, float sigma, float nl, float nv) {
  float eavg = mp_oren_nayar_average(sigma);
  float k = (1.0f - mp_oren_nayar_albedo(nl, sigma)) * (1.0f - mp_oren_nayar_albedo(nv, sigma));
  return MP_F3(mp_eon_ms_scale(rho.x, eavg), mp_eon_ms_scale(rho.y, eavg), mp_eon_ms_scale(rho.z, eavg)) * k;
}
/* The same lobe's directional albedo: rho_ms (1 - E(nv)) (its integral of
 * (1 - E(nl)) cos is pi (1 - Eavg)). */
MP_INLINE float3 mp_eon_ms_albedo(float3 rho, float sigma, float nv) {
  float eavg = mp_oren_nayar_average(sigma), k = MP_BSDF_PI * (1.0f - eavg) * (1.0f - mp_oren_nayar_albedo(nv, sigma));
  return MP_F3(mp_eon_ms_scale(rho.x, eavg), mp_eon_ms_scale(rho.y, eavg), mp_eon_ms_scale(rho.z, eavg)) * k;
}

/* Disney's diffuse with retro-reflection (Principled 3.x), f cos:
 * nl / pi ((1 - FL/2)(1 - FV/2) + R (FL + FV + FL FV (R - 1))), F = (1 - cos)^5,
 * R = roughness (1 + l.v). */
MP_INLINE float mp_disney_diffuse(float3 n, float3 l, float3 v, float roughness) {
  float nl = fmax(dot(n, l), 0.0f), nv = fmax(dot(n, v), 0.0f);
  float fl = mp_schlick_weight(nl), fv = mp_schlick_weight(nv);
  float rr = roughness * (1.0f + dot(l, v));
  return nl * (1.0f / MP_BSDF_PI) * ((1.0f - 0.5f * fl) * (1.0f - 0.5f * fv) + rr * (fl + fv + fl * fv * (rr - 1.0f)));
}

/* Ashikhmin's velvet (Cycles' Velvet BSDF, and Sheen BSDF's Ashikhmin):
 * an inverted-Gaussian distribution of width sigma, f cos. */
MP_INLINE float mp_velvet(float3 n, float3 l, float3 v, float sigma) {
  float nv = dot(n, v), nl = dot(n, l);
  if (!(nv > 0.0f && nl > 0.0f)) return 0.0f;
  float3 h = normalize(l + v);
  float nh = dot(n, h), hv = fabs(dot(v, h));
  if (!(fabs(nh) < 0.99999f && hv > 1e-5f)) return 0.0f;
  float inv_s2 = 1.0f / fmax(sigma * sigma, 1e-4f);
  float q = fmax(nh / hv, 1e-5f);
  float g = fmin(1.0f, fmin(2.0f * fabs(q * nv), 2.0f * fabs(q * nl)));
  float s2 = 1.0f - nh * nh;
  float d = exp(-(nh * nh / s2) * inv_s2) * inv_s2 * (1.0f / MP_BSDF_PI) / (s2 * s2);
  return 0.25f * d * g / nv;
}

/* Toon: full intensity within `size` (of a right angle) of the axis, a
 * linear fall over `smooth` beyond, normalised over the cone it can
 * reach, as Cycles' Toon BSDF. angle_cos: cosine to the lobe's axis (n for
 * diffuse, the mirror direction for glossy). */
MP_INLINE float mp_toon(float angle_cos, float size, float smooth) {
  float max_angle = size * 0.5f * MP_BSDF_PI, sm = smooth * 0.5f * MP_BSDF_PI;
  float angle = acos(clamp(angle_cos, 0.0f, 1.0f));
  float is = angle < max_angle ? 1.0f : (sm > 0.0f && angle < max_angle + sm) ? 1.0f - (angle - max_angle) / sm : 0.0f;
  float sample_angle = fmin(max_angle + sm, 0.5f * MP_BSDF_PI);
  float denom = 1.0f - cos(sample_angle);
  return denom > 0.0f ? is * 0.5f / (MP_BSDF_PI * denom) : 0.0f;
}

/* The Charlie sheen distribution's directional albedo (Estevez and Kulla
 * 2017, D = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi) with a = roughness^2,
 * with Neubelt and Pettineo's visibility 1 / (4 (nl + nv - nl nv))), by
 * quadrature (scripts/tables/microfiber_sheen_table.py), on a 9 x 9 grid of nv
 * (rows, 0.02 then 0.125 .. 1) and roughness (columns, 0.05 then 0.125 ..
 * 1), read bilinearly; it stands in for the velvet lobe's albedo. */
MP_CONSTANT float mp_charlie_sheen_table[81] = {3.9337f,2.3146f,1.3820f,1.0206f,0.8375f,0.7312f,0.6642f,0.6195f,0.5882f,0.2294f,0.7300f,0.7482f,0.6634f,0.5958f,0.5481f,0.5146f,0.4907f,0.4734f,0.0037f,0.1925f,0.3945f,0.4334f,0.4314f,0.4209f,0.4102f,0.4012f,0.3939f,0.0000f,0.0431f,0.2041f,0.2844f,0.3165f,0.3289f,0.3336f,0.3351f,0.3352f,0.0000f,0.0073f,0.0989f,0.1819f,0.2296f,0.2561f,0.2716f,0.2811f,0.2873f,0.0000f,0.0008f,0.0428f,0.1103f,0.1616f,0.1960f,0.2189f,0.2346f,0.2458f,0.0000f,0.0000f,0.0153f,0.0609f,0.1077f,0.1450f,0.1727f,0.1932f,0.2085f,0.0000f,0.0000f,0.0037f,0.0280f,0.0650f,0.1010f,0.1313f,0.1553f,0.1740f,0.0000f,0.0000f,0.0002f,0.0077f,0.0313f,0.0628f,0.0935f,0.1198f,0.1414f};

MP_INLINE float mp_charlie_sheen_albedo(float nv, float roughness) {
  float x = clamp(nv, 0.0f, 1.0f) * 8.0f, y = clamp(roughness, 0.0f, 1.0f) * 8.0f;
  int i = (int)fmin(floor(x), 7.0f), j = (int)fmin(floor(y), 7.0f);
  float fx = x - (float)i, fy = y - (float)j;
  int k = 9 * i + j;
  float e = (1.0f - fx) * ((1.0f - fy) * mp_charlie_sheen_table[k] + fy * mp_charlie_sheen_table[k + 1]) +
            fx * ((1.0f - fy) * mp_charlie_sheen_table[k + 9] + fy * mp_charlie_sheen_table[k + 10]);
  return fmin(e, 1.0f);
}

/* Sheen of microfibers (Sheen BSDF's Microfiber and Principled 4.x sheen),
 * as Cycles evaluates it: a linearly transformed cosine (Zeltner et al.
 * 2022) in the frame whose x axis T is the view's direction along the
 * surface, f cos = s z (a / ((a x + b z)^2 + (a y)^2 + z^2))^2 / pi for the
 * light's direction (x, y, z), with a, b and s (the lobe's directional
 * albedo) functions of the view's cosine and the roughness. Cycles reads
 * them from tables of its own; mp_sheen_ltc_table.h holds them as fitted to
 * Cycles 4.5's renders of the lobe (scripts/tables/sheen_ltc_cycles.py). */

#ifdef MP_MICROFIBER_SHEEN
/* A place on the LTC table's axes (0.02, then 1/16 .. 1 in sixteenths):
 * its cell (0 .. 15) and the fraction t across it. */
MP_INLINE int mp_sheen_ltc_cell(float x, float* t) {
  x = clamp(x, 0.0f, 1.0f);
  float u = x < 0.0625f ? fmax(x - 0.02f, 0.0f) * (1.0f / (0.0625f - 0.02f)) : 16.0f * x;
  int i = (int)fmin(floor(u), 15.0f);
  *t = u - (float)i;
  return i;
}

/* Parameter k (0: a, 1: b, 2: s) in the cells at (i, j), read bilinearly. */
MP_INLINE float mp_sheen_ltc(int k, int i, float ti, int j, float tj) {
  int at = k * 289 + 17 * i + j;
  return (1.0f - ti) * ((1.0f - tj) * mp_sheen_ltc_table[at] + tj * mp_sheen_ltc_table[at + 1]) +
         ti * ((1.0f - tj) * mp_sheen_ltc_table[at + 17] + tj * mp_sheen_ltc_table[at + 18]);
}

/* The lobe's transform and albedo (a, b, s) at view cosine nv. */
MP_INLINE float3 mp_microfiber_sheen_ltc(float nv, float roughness) {
  float ti, tj;
  int i = mp_sheen_ltc_cell(nv, &ti), j = mp_sheen_ltc_cell(roughness, &tj);
  return MP_F3(mp_sheen_ltc(0, i, ti, j, tj), mp_sheen_ltc(1, i, ti, j, tj), fmax(mp_sheen_ltc(2, i, ti, j, tj), 0.0f));
}

/* The microfiber sheen's directional albedo: Cycles'. */
MP_INLINE float mp_microfiber_sheen_albedo(float nv, float roughness) { return mp_microfiber_sheen_ltc(nv, roughness).z; }

#endif

/* The microfiber sheen lobe times cos, of transform and albedo ltc = (a, b,
 * s) (mp_microfiber_sheen_ltc at the view's cosine): shading reads them once
 * per closure, before its lamps. */
MP_INLINE float mp_microfiber_sheen_lobe(float3 n, float3 l, float3 v, float3 ltc) {
  float nl = dot(n, l), nv = dot(n, v);
  float a = ltc.x, b = ltc.y, s = ltc.z;
  /* Cycles skips a lobe whose transform or albedo vanishes. */
  if (!(nl > 0.0f && nv > 0.0f && fabs(a) >= 1e-5f && s >= 1e-5f)) return 0.0f;
  /* T: the view along the surface (any tangent when the view is the normal). */
  float3 t = v - n * nv;
  float tt = dot(t, t);
  if (!(tt > 1e-12f)) {
    t = cross(n, fabs(n.x) < 0.9f ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f));
    tt = dot(t, t);
  }
  t = t * (1.0f / sqrt(tt));
  float3 bt = cross(n, t);
  float x = dot(l, t), y = dot(l, bt), z = nl;
  float ax = a * x + b * z, ay = a * y;
  float q = a / (ax * ax + ay * ay + z * z);
  return s * z * q * q * (1.0f / MP_BSDF_PI);
}

#ifdef MP_MICROFIBER_SHEEN
/* The same, reading the tables at the view's cosine. */
MP_INLINE float mp_microfiber_sheen(float3 n, float3 l, float3 v, float roughness) {
  return mp_microfiber_sheen_lobe(n, l, v, mp_microfiber_sheen_ltc(fmax(dot(n, v), 0.0f), roughness));
}
#endif

#endif
