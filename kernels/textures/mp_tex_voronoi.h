/* Voronoi Texture node with Blender's conventions: one jittered feature
 * point per unit cell (jitter = Randomness), searched over the 3^n (5^n for
 * Smooth F1) surrounding cells in x-fastest order; F1, F2, Smooth F1 (smooth
 * minimum after Inigo Quilez), Distance to Edge (Quilez's cell-border
 * distance), N-Sphere Radius; Euclidean, Manhattan, Chebychev and Minkowski
 * metrics (1D always uses |a - b|; edge and radius are always Euclidean);
 * from Blender 4.0 on the fractal Detail/Roughness/Lacunarity/Normalize
 * inputs; from Blender 5.0 on integer cell hashing in 2D-4D.
 *
 * Points of 1-4 dimensions travel as private float arrays (x, y, z, w).
 * Compiles as OpenCL C 1.2 and C++17 through mp_compat.h. */
#ifndef MP_TEX_VORONOI_H
#define MP_TEX_VORONOI_H

#include "core/mp_compat.h"
#include "textures/mp_blender_hash.h"
#include "textures/mp_tex_noise.h"

#define MP_VORONOI_F1 0
#define MP_VORONOI_F2 1
#define MP_VORONOI_SMOOTH_F1 2
#define MP_VORONOI_DISTANCE_TO_EDGE 3
#define MP_VORONOI_N_SPHERE_RADIUS 4

#define MP_VORONOI_EUCLIDEAN 0
#define MP_VORONOI_MANHATTAN 1
#define MP_VORONOI_CHEBYCHEV 2
#define MP_VORONOI_MINKOWSKI 3

#define MP_TX_FLT_MAX 3.402823466e+38f

/* Sum of four terms the way a 4-wide horizontal add does it. */
MP_INLINE float mp_tx_sum(const float* t, int dims, int pairwise) {
  if (dims == 4 && pairwise) return (t[0] + t[1]) + (t[2] + t[3]);
  float s = t[0];
  for (int k = 1; k < dims; k++) s += t[k];
  return s;
}

MP_INLINE float mp_tx_dot(const float* a, const float* b, int dims) {
  float t[4];
  for (int k = 0; k < dims; k++) t[k] = a[k] * b[k];
  return mp_tx_sum(t, dims, 1);
}

MP_INLINE float mp_tx_dist_euclid(const float* a, const float* b, int dims) {
  float d[4];
  for (int k = 0; k < dims; k++) d[k] = a[k] - b[k];
  return sqrt(mp_tx_dot(d, d, dims));
}

/* Distance between a and b in the node's metric. With `bound` set the
 * monotone stand-in used for picking the nearest point (squared Euclidean,
 * Minkowski without the final root), as Blender 4.5 compares. */
MP_INLINE float mp_tx_vor_metric(const float* a, const float* b, int dims, int metric, float exponent, int bound,
                                 int ver) {
  if (dims == 1) return fabs(b[0] - a[0]);
  float t[4];
  for (int k = 0; k < dims; k++) t[k] = fabs(a[k] - b[k]);
  int pairwise = ver >= 400;
  if (metric == MP_VORONOI_EUCLIDEAN) {
    float s = mp_tx_dot(t, t, dims);
    return bound ? s : sqrt(s);
  }
  if (metric == MP_VORONOI_MANHATTAN) return mp_tx_sum(t, dims, pairwise);
  if (metric == MP_VORONOI_CHEBYCHEV) {
    float m = t[0];
    for (int k = 1; k < dims; k++) m = fmax(m, t[k]);
    return m;
  }
  if (metric == MP_VORONOI_MINKOWSKI) {
    for (int k = 0; k < dims; k++) t[k] = pow(t[k], exponent);
    float s = mp_tx_sum(t, dims, pairwise);
    return bound ? s : pow(s, 1.0f / exponent);
  }
  return 0.0f;
}

/* Jitter in [0, 1]^dims of cell `cell + off`. */
MP_INLINE void mp_tx_vor_cell_hash(const float* cell, const int* off, int dims, int ver, float* h) {
  if (dims == 1) {
    h[0] = mp_bhash_float_to_float(cell[0] + (float)off[0]);
    return;
  }
  if (ver >= 500) {
    int c[4];
    for (int k = 0; k < dims; k++) c[k] = (int)cell[k] + off[k];
    if (dims == 2) mp_bhash_int2_to_float2(c[0], c[1], h);
    else if (dims == 3) mp_bhash_int3_to_float3v(c[0], c[1], c[2], h);
    else mp_bhash_int4_to_float4(c[0], c[1], c[2], c[3], h);
    return;
  }
  float c[4];
  for (int k = 0; k < dims; k++) c[k] = cell[k] + (float)off[k];
  if (dims == 2) mp_bhash_float2_to_float2(c[0], c[1], h);
  else if (dims == 3) mp_bhash_float3_to_float3v(c[0], c[1], c[2], h);
  else mp_bhash_float4_to_float4(c[0], c[1], c[2], c[3], h);
}

/* Colour of cell `cell + off`. */
MP_INLINE float3 mp_tx_vor_cell_color(const float* cell, const int* off, int dims, int ver) {
  if (dims == 1) return mp_bhash_float_to_float3(cell[0] + (float)off[0]);
  if (ver >= 500) {
    int c[4];
    for (int k = 0; k < dims; k++) c[k] = (int)cell[k] + off[k];
    if (dims == 2) return mp_bhash_int2_to_float3(c[0], c[1]);
    if (dims == 3) return mp_bhash_int3_to_float3(c[0], c[1], c[2]);
    return mp_bhash_int4_to_float3(c[0], c[1], c[2], c[3]);
  }
  float c[4];
  for (int k = 0; k < dims; k++) c[k] = cell[k] + (float)off[k];
  if (dims == 2) return mp_bhash_float2_to_float3(c[0], c[1]);
  if (dims == 3) return mp_bhash_float3_to_float3(MP_F3(c[0], c[1], c[2]));
  return mp_bhash_float4_to_float3(c[0], c[1], c[2], c[3]);
}

/* Offset number n of a (2r+1)^dims neighbourhood, x varying fastest. */
MP_INLINE void mp_tx_vor_offset(int n, int r, int dims, int* off) {
  int side = 2 * r + 1;
  for (int k = 0; k < dims; k++) {
    off[k] = n % side - r;
    n /= side;
  }
}

MP_INLINE int mp_tx_ipow(int b, int e) {
  int r = 1;
  for (int i = 0; i < e; i++) r *= b;
  return r;
}

/* Feature point of cell `cell + off`, relative to `cell`. */
MP_INLINE void mp_tx_vor_point(const float* cell, const int* off, int dims, float randomness, int ver, float* pt) {
  float h[4];
  mp_tx_vor_cell_hash(cell, off, dims, ver, h);
  for (int k = 0; k < dims; k++) pt[k] = (float)off[k] + h[k] * randomness;
}

/* One octave of F1, F2 or Smooth F1 at `coord`. Writes the distance, the
 * cell colour and the feature position (dims components). */
MP_INLINE void mp_tx_voronoi_octave(const float* coord, int dims, int feature, int metric, float exponent,
                                    float randomness, float smoothness, int ver, float* dist, float3* color,
                                    float* pos) {
  float cell[4], lpos[4];
  for (int k = 0; k < dims; k++) {
    cell[k] = floor(coord[k]);
    lpos[k] = coord[k] - cell[k];
  }
  float far_init = ver < 400 ? 8.0f : MP_TX_FLT_MAX;

  if (feature == MP_VORONOI_SMOOTH_F1) {
    float sdist = ver < 400 ? 8.0f : 0.0f;
    float3 scol = MP_F3(0.0f, 0.0f, 0.0f);
    float spos[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    float h = -1.0f;
    int count = mp_tx_ipow(5, dims);
    for (int n = 0; n < count; n++) {
      int off[4];
      float pt[4];
      mp_tx_vor_offset(n, 2, dims, off);
      mp_tx_vor_point(cell, off, dims, randomness, ver, pt);
      float d = mp_tx_vor_metric(pt, lpos, dims, metric, exponent, 0, ver);
      if (ver < 400 || h != -1.0f) h = mp_tx_smoothstep(0.0f, 1.0f, 0.5f + 0.5f * (sdist - d) / smoothness);
      else h = 1.0f;
      float corr = smoothness * h * (1.0f - h);
      sdist = mp_tx_mix(sdist, d, h) - corr;
      corr /= 1.0f + 3.0f * smoothness;
      float3 cc = mp_tx_vor_cell_color(cell, off, dims, ver);
      scol.x = mp_tx_mix(scol.x, cc.x, h) - corr;
      scol.y = mp_tx_mix(scol.y, cc.y, h) - corr;
      scol.z = mp_tx_mix(scol.z, cc.z, h) - corr;
      for (int k = 0; k < dims; k++) spos[k] = mp_tx_mix(spos[k], pt[k], h) - corr;
    }
    *dist = sdist;
    *color = scol;
    for (int k = 0; k < dims; k++) pos[k] = cell[k] + spos[k];
    return;
  }

  int count = mp_tx_ipow(3, dims);
  if (feature == MP_VORONOI_F2) {
    float d1 = far_init, d2 = far_init;
    int o1[4] = {0, 0, 0, 0}, o2[4] = {0, 0, 0, 0};
    float p1[4] = {0.0f, 0.0f, 0.0f, 0.0f}, p2[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int n = 0; n < count; n++) {
      int off[4];
      float pt[4];
      mp_tx_vor_offset(n, 1, dims, off);
      mp_tx_vor_point(cell, off, dims, randomness, ver, pt);
      float d = mp_tx_vor_metric(pt, lpos, dims, metric, exponent, 0, ver);
      if (d < d1) {
        d2 = d1;
        d1 = d;
        for (int k = 0; k < dims; k++) {
          o2[k] = o1[k];
          o1[k] = off[k];
          p2[k] = p1[k];
          p1[k] = pt[k];
        }
      }
      else if (d < d2) {
        d2 = d;
        for (int k = 0; k < dims; k++) {
          o2[k] = off[k];
          p2[k] = pt[k];
        }
      }
    }
    *dist = d2;
    *color = mp_tx_vor_cell_color(cell, o2, dims, ver);
    for (int k = 0; k < dims; k++) pos[k] = p2[k] + cell[k];
    return;
  }

  /* F1. Blender 4.5+ picks the nearest point by a cheaper monotone bound. */
  int bound = ver >= 405;
  float dmin = far_init;
  int o1[4] = {0, 0, 0, 0};
  float p1[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int n = 0; n < count; n++) {
    int off[4];
    float pt[4];
    mp_tx_vor_offset(n, 1, dims, off);
    mp_tx_vor_point(cell, off, dims, randomness, ver, pt);
    float d = mp_tx_vor_metric(pt, lpos, dims, metric, exponent, bound, ver);
    if (d < dmin) {
      dmin = d;
      for (int k = 0; k < dims; k++) {
        o1[k] = off[k];
        p1[k] = pt[k];
      }
    }
  }
  *dist = bound ? mp_tx_vor_metric(p1, lpos, dims, metric, exponent, 0, ver) : dmin;
  *color = mp_tx_vor_cell_color(cell, o1, dims, ver);
  for (int k = 0; k < dims; k++) pos[k] = p1[k] + cell[k];
}

/* Distance from `coord` to the nearest cell border. */
MP_INLINE float mp_tx_voronoi_edge(const float* coord, int dims, float randomness, int ver) {
  float cell[4], lpos[4];
  for (int k = 0; k < dims; k++) {
    cell[k] = floor(coord[k]);
    lpos[k] = coord[k] - cell[k];
  }
  if (dims == 1) {
    int o0[1] = {0}, om[1] = {-1}, op[1] = {1};
    float hm[1], h0[1], hp[1];
    mp_tx_vor_cell_hash(cell, o0, 1, ver, h0);
    mp_tx_vor_cell_hash(cell, om, 1, ver, hm);
    mp_tx_vor_cell_hash(cell, op, 1, ver, hp);
    float mid = h0[0] * randomness;
    float left = -1.0f + hm[0] * randomness;
    float right = 1.0f + hp[0] * randomness;
    float dl = fabs((mid + left) / 2.0f - lpos[0]);
    float dr = fabs((mid + right) / 2.0f - lpos[0]);
    return fmin(dl, dr);
  }
  float far_init = ver < 400 ? 8.0f : MP_TX_FLT_MAX;
  int count = mp_tx_ipow(3, dims);
  float to_closest[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  float dmin = far_init;
  for (int n = 0; n < count; n++) {
    int off[4];
    float v[4];
    mp_tx_vor_offset(n, 1, dims, off);
    mp_tx_vor_point(cell, off, dims, randomness, ver, v);
    for (int k = 0; k < dims; k++) v[k] -= lpos[k];
    float d = mp_tx_dot(v, v, dims);
    if (d < dmin) {
      dmin = d;
      for (int k = 0; k < dims; k++) to_closest[k] = v[k];
    }
  }
  dmin = far_init;
  for (int n = 0; n < count; n++) {
    int off[4];
    float v[4], perp[4], mid[4];
    mp_tx_vor_offset(n, 1, dims, off);
    mp_tx_vor_point(cell, off, dims, randomness, ver, v);
    for (int k = 0; k < dims; k++) {
      v[k] -= lpos[k];
      perp[k] = v[k] - to_closest[k];
    }
    if (mp_tx_dot(perp, perp, dims) > 0.0001f) {
      float len = sqrt(mp_tx_dot(perp, perp, dims));
      for (int k = 0; k < dims; k++) {
        mid[k] = (to_closest[k] + v[k]) / 2.0f;
        perp[k] = perp[k] / len;
      }
      dmin = fmin(dmin, mp_tx_dot(mid, perp, dims));
    }
  }
  return dmin;
}

/* Half the distance from the nearest feature point to its own nearest. */
MP_INLINE float mp_tx_voronoi_radius(const float* coord, int dims, float randomness, int ver) {
  float cell[4], lpos[4];
  for (int k = 0; k < dims; k++) {
    cell[k] = floor(coord[k]);
    lpos[k] = coord[k] - cell[k];
  }
  int squared = ver >= 405 && dims > 1;
  float far_init = ver < 400 ? 8.0f : MP_TX_FLT_MAX;
  int count = mp_tx_ipow(3, dims);
  float closest[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  int closest_off[4] = {0, 0, 0, 0};
  float dmin = far_init;
  for (int n = 0; n < count; n++) {
    int off[4];
    float pt[4];
    mp_tx_vor_offset(n, 1, dims, off);
    mp_tx_vor_point(cell, off, dims, randomness, ver, pt);
    float d;
    if (dims == 1) d = fabs(pt[0] - lpos[0]);
    else if (squared) {
      float t[4];
      for (int k = 0; k < dims; k++) t[k] = pt[k] - lpos[k];
      d = mp_tx_dot(t, t, dims);
    }
    else d = mp_tx_dist_euclid(pt, lpos, dims);
    if (d < dmin) {
      dmin = d;
      for (int k = 0; k < dims; k++) {
        closest[k] = pt[k];
        closest_off[k] = off[k];
      }
    }
  }
  dmin = far_init;
  float second[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int n = 0; n < count; n++) {
    int off[4];
    float pt[4];
    mp_tx_vor_offset(n, 1, dims, off);
    int center = 1;
    for (int k = 0; k < dims; k++) {
      if (off[k] != 0) center = 0;
      off[k] += closest_off[k];
    }
    if (center) continue;
    mp_tx_vor_point(cell, off, dims, randomness, ver, pt);
    float d;
    if (dims == 1) d = fabs(closest[0] - pt[0]);
    else if (squared) {
      float t[4];
      for (int k = 0; k < dims; k++) t[k] = closest[k] - pt[k];
      d = mp_tx_dot(t, t, dims);
    }
    else d = mp_tx_dist_euclid(closest, pt, dims);
    if (d < dmin) {
      dmin = d;
      for (int k = 0; k < dims; k++) second[k] = pt[k];
    }
  }
  if (dims == 1) return fabs(second[0] - closest[0]) / 2.0f;
  return mp_tx_dist_euclid(second, closest, dims) / 2.0f;
}

/* Positions travel as (x, y, z, w): 1D lives in w, 2D in x, y, 3D in x, y, z. */
MP_INLINE void mp_tx_vor_to_xyzw(const float* pos, int dims, float* out) {
  out[0] = 0.0f;
  out[1] = 0.0f;
  out[2] = 0.0f;
  out[3] = 0.0f;
  if (dims == 1) {
    out[3] = pos[0];
    return;
  }
  for (int k = 0; k < dims; k++) out[k] = pos[k];
}

/* Voronoi Texture node. Inputs as the node's sockets receive them; dims 1
 * uses W only, 2 p.xy, 3 p.xyz, 4 (p, W). feature 0 F1, 1 F2, 2 Smooth F1,
 * 3 Distance to Edge, 4 N-Sphere Radius; metric 0 Euclidean, 1 Manhattan,
 * 2 Chebychev, 3 Minkowski. detail/roughness/lacunarity/normalize are the
 * Blender 4.0+ fractal inputs (ignored before). Outputs not produced by the
 * feature are 0, as in Blender. */
MP_INLINE void mp_tex_voronoi(float3 p, float w, int dims, int feature, int metric, float scale, float detail,
                              float roughness, float lacunarity, float smoothness, float exponent, float randomness,
                              int normalize, int blender_version, float* distance, float3* color, float3* position,
                              float* w_out, float* radius) {
  int ver = blender_version;
  dims = clamp(dims, 1, 4);
  randomness = clamp(randomness, 0.0f, 1.0f);
  smoothness = clamp(smoothness / 2.0f, 0.0f, 0.5f);
  if (ver >= 400) {
    detail = clamp(detail, 0.0f, 15.0f);
    roughness = clamp(roughness, 0.0f, 1.0f);
  }
  float coord[4];
  if (dims == 1) {
    coord[0] = w * scale;
  }
  else {
    coord[0] = p.x * scale;
    coord[1] = p.y * scale;
    coord[2] = p.z * scale;
    coord[3] = w * scale;
  }

  *distance = 0.0f;
  *color = MP_F3(0.0f, 0.0f, 0.0f);
  *position = MP_F3(0.0f, 0.0f, 0.0f);
  *w_out = 0.0f;
  *radius = 0.0f;

  if (feature == MP_VORONOI_N_SPHERE_RADIUS) {
    *radius = mp_tx_voronoi_radius(coord, dims, randomness, ver);
    return;
  }

  if (ver < 400) {
    /* One octave; positions back in unscaled space. */
    if (feature == MP_VORONOI_DISTANCE_TO_EDGE) {
      *distance = mp_tx_voronoi_edge(coord, dims, randomness, ver);
      return;
    }
    float d, pos[4], q[4];
    float3 c;
    mp_tx_voronoi_octave(coord, dims, feature, metric, exponent, randomness, smoothness, ver, &d, &c, pos);
    mp_tx_vor_to_xyzw(pos, dims, q);
    *distance = d;
    *color = c;
    *position = MP_F3(mp_tx_safe_divide(q[0], scale), mp_tx_safe_divide(q[1], scale), mp_tx_safe_divide(q[2], scale));
    *w_out = mp_tx_safe_divide(q[3], scale);
    return;
  }

  /* Blender 4.0+: octaves at lacunarity^i frequency with roughness^i weights;
   * a fractional detail blends in one more octave. */
  int zero_input = detail == 0.0f || roughness == 0.0f;
  float amplitude = 1.0f, octave_scale = 1.0f;
  int last = (int)ceil(detail);

  if (feature == MP_VORONOI_DISTANCE_TO_EDGE) {
    float max_distance = 0.5f + 0.5f * randomness;
    float max_amplitude = max_distance;
    float dist = 8.0f;
    for (int i = 0; i <= last; i++) {
      float q[4];
      for (int k = 0; k < dims; k++) q[k] = coord[k] * octave_scale;
      float od = mp_tx_voronoi_edge(q, dims, randomness, ver);
      if (zero_input) {
        dist = od;
        break;
      }
      if ((float)i <= detail) {
        max_amplitude = mp_tx_mix(max_amplitude, max_distance / octave_scale, amplitude);
        dist = mp_tx_mix(dist, fmin(dist, od / octave_scale), amplitude);
        octave_scale *= lacunarity;
        amplitude *= roughness;
      }
      else {
        float remainder = detail - floor(detail);
        if (remainder != 0.0f) {
          float lerp_amplitude = mp_tx_mix(max_amplitude, max_distance / octave_scale, amplitude);
          max_amplitude = mp_tx_mix(max_amplitude, lerp_amplitude, remainder);
          float lerp_distance = mp_tx_mix(dist, fmin(dist, od / octave_scale), amplitude);
          dist = mp_tx_mix(dist, fmin(dist, lerp_distance), remainder);
        }
      }
    }
    if (normalize) dist /= max_amplitude;
    *distance = dist;
    return;
  }

  /* Largest F1 (twice for F2) distance, for Normalize. */
  float max_distance;
  {
    float c = 0.5f + 0.5f * randomness;
    if (dims == 1) {
      max_distance = c;
    }
    else {
      float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f}, corner[4] = {c, c, c, c};
      max_distance = mp_tx_vor_metric(zero, corner, dims, metric, exponent, 0, ver);
    }
    if (feature == MP_VORONOI_F2) max_distance *= 2.0f;
  }
  /* Smooth F1 with zero smoothness is plain F1. */
  int octave_feature = feature;
  if (feature == MP_VORONOI_SMOOTH_F1 && smoothness == 0.0f) octave_feature = MP_VORONOI_F1;

  float max_amplitude = 0.0f;
  float out_d = 0.0f;
  float out_c[3] = {0.0f, 0.0f, 0.0f};
  float out_p[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int i = 0; i <= last; i++) {
    float q[4], od, opos[4], op4[4];
    float3 oc;
    for (int k = 0; k < dims; k++) q[k] = coord[k] * octave_scale;
    mp_tx_voronoi_octave(q, dims, octave_feature, metric, exponent, randomness, smoothness, ver, &od, &oc, opos);
    mp_tx_vor_to_xyzw(opos, dims, op4);
    if (zero_input) {
      max_amplitude = 1.0f;
      out_d = od;
      out_c[0] = oc.x;
      out_c[1] = oc.y;
      out_c[2] = oc.z;
      for (int k = 0; k < 4; k++) out_p[k] = op4[k];
      break;
    }
    if ((float)i <= detail) {
      max_amplitude += amplitude;
      out_d += od * amplitude;
      out_c[0] += oc.x * amplitude;
      out_c[1] += oc.y * amplitude;
      out_c[2] += oc.z * amplitude;
      for (int k = 0; k < 4; k++) out_p[k] = mp_tx_mix(out_p[k], op4[k] / octave_scale, amplitude);
      octave_scale *= lacunarity;
      amplitude *= roughness;
    }
    else {
      float remainder = detail - floor(detail);
      if (remainder != 0.0f) {
        max_amplitude = mp_tx_mix(max_amplitude, max_amplitude + amplitude, remainder);
        out_d = mp_tx_mix(out_d, out_d + od * amplitude, remainder);
        out_c[0] = mp_tx_mix(out_c[0], out_c[0] + oc.x * amplitude, remainder);
        out_c[1] = mp_tx_mix(out_c[1], out_c[1] + oc.y * amplitude, remainder);
        out_c[2] = mp_tx_mix(out_c[2], out_c[2] + oc.z * amplitude, remainder);
        for (int k = 0; k < 4; k++)
          out_p[k] = mp_tx_mix(out_p[k], mp_tx_mix(out_p[k], op4[k] / octave_scale, amplitude), remainder);
      }
    }
  }
  if (normalize) {
    out_d /= max_amplitude * max_distance;
    for (int k = 0; k < 3; k++) out_c[k] /= max_amplitude;
  }
  *distance = out_d;
  *color = MP_F3(out_c[0], out_c[1], out_c[2]);
  *position = MP_F3(mp_tx_safe_divide(out_p[0], scale), mp_tx_safe_divide(out_p[1], scale),
                    mp_tx_safe_divide(out_p[2], scale));
  *w_out = mp_tx_safe_divide(out_p[3], scale);
}

#endif
