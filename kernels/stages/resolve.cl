/* Resolve: reconstruct pixels from samples with a pixel filter. Color is
 * premultiplied by coverage and alpha is the filtered coverage, as Blender's
 * render result expects. Depth is the nearest covered sample's camera-space
 * depth (1e10 where nothing is covered, as Blender's Z pass); Normal is the
 * mean world-space normal of the pixel's covered samples. */
#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "core/mp_hash.h"
#include "stages/mp_raster.h"
#include "stages/mp_sample.h"

#define MP_NO_DEPTH 1.0e10f

__kernel void clear_samples(__global ulong* keys, ulong n) {
  ulong i = get_global_id(0);
  if (i < n) keys[i] = (ulong)0xffffffffffffffffUL;
}

/* One work-item per pixel of the region [region.x, region.z) x [region.y,
 * region.w) of the sample buffer (a bucket's pixels, buckets.h), written to
 * the image (out_width pixels wide) at its pixel plus `origin`.
 * `weights`, when use_weights is set, holds the filter weight of every sample
 * of every neighbour for each of the 32x32 positions a pixel can have in the
 * repeating sample tile (built on the host from the same functions), so the
 * filter is not re-evaluated per sample. */
#define MP_RESOLVE_ARGS                                                                                              \
  FrameParams f, int filter_type, float filter_width, __global const ushort *offsets, __global const float *weights,  \
      int use_weights, __global const ulong *keys, __global const float *colors, __global const uint *normals,        \
      float4 cam_to_world_x, float4 cam_to_world_y, float4 cam_to_world_z, __global float4 *rgba,                     \
      __global float *depth, __global float *normal_out, int want_passes, int4 region, int2 origin, int out_width
#define MP_RESOLVE_PASS                                                                                              \
  f, filter_type, filter_width, offsets, weights, use_weights, keys, colors, normals, cam_to_world_x, cam_to_world_y, \
      cam_to_world_z, rgba, depth, normal_out, want_passes, region, origin, out_width

inline void mp_resolve_write(MP_RESOLVE_ARGS, int px, int py, float4 sum, float wsum);

/* `lanes` (a constant in each kernel below): planar sample colors
 * (FrameParams.planar_colors, the tile sampler's) summed 8 at a time; the
 * other kernel carries none of that code, whose registers cost GPUs
 * occupancy. */
inline void mp_resolve(MP_RESOLVE_ARGS, const int lanes) {
  int px = region.x + (int)get_global_id(0), py = region.y + (int)get_global_id(1);
  if (px >= region.z || py >= region.w) return;
  int spp = f.spp_x * f.spp_y;
  int reach = mp_filter_reach(filter_width);
  float4 sum = (float4)(0.0f);
  float wsum = 0.0f;
  /* Sums of the 8-lane loop, added in once at the end. Eight lanes, not
   * sixteen: the x86 backend of LLVM 14 (in the PoCL that the extension
   * carries, docs/install.md) aborts on this loop's 16-wide compares. */
  float8 r8 = (float8)(0.0f), g8 = (float8)(0.0f), b8 = (float8)(0.0f), a8 = (float8)(0.0f), w8 = (float8)(0.0f);
  float cx = (float)px + 0.5f, cy = (float)py + 0.5f;
  int side = 2 * reach + 1;
  int tile = ((py + f.crop_y0) & (MP_SAMPLE_TILE - 1)) * MP_SAMPLE_TILE + ((px + f.crop_x0) & (MP_SAMPLE_TILE - 1));
  for (int qy = max(py - reach, 0); qy <= min(py + reach, f.height - 1); ++qy)
    for (int qx = max(px - reach, 0); qx <= min(px + reach, f.width - 1); ++qx) {
      __global const float* wrow = weights + ((ulong)tile * (ulong)(side * side) +
                                              (ulong)((qy - py + reach) * side + (qx - px + reach))) * (ulong)spp;
      ulong q = (ulong)qy * (ulong)f.width + (ulong)qx;
      int s = 0;
      if (lanes && use_weights && spp >= 8) {
        /* 8 samples at a time (the weights and each color channel of a
         * pixel's samples lie together, mp_sample.h). */
        __global const ulong* k = keys + q * (ulong)spp;
        __global const float* c = colors + mp_color_index(q, spp, 0);
        for (; s + 8 <= spp; s += 8) {
          float8 w = vload8(0, wrow + s);
          w = select((float8)(0.0f), w, w > (float8)(0.0f));
          /* Empty samples' colors are whatever the buffer held: selected
           * away, not multiplied by 0 (which keeps a NaN). */
          int8 covered = convert_int8(vload8(0, k + s) != (ulong8)0xffffffffffffffffUL);
          /* A sample's held-out share (mp_sample.h) is left out of its
           * alpha, unless f.holdout_covers; its colour has it already. */
          float8 blue = vload8(0, c + 2 * spp + s);
          float8 shown = f.holdout_covers || !f.holdouts
                             ? w
                             : w * (1.0f - convert_float8(as_uint8(blue) & (uint8)(0xffu)) * (1.0f / 255.0f));
          w8 += w;
          a8 += select((float8)(0.0f), shown, covered);
          r8 += select((float8)(0.0f), w * vload8(0, c + s), covered);
          g8 += select((float8)(0.0f), w * vload8(0, c + spp + s), covered);
          b8 += select((float8)(0.0f), w * blue, covered);
        }
      }
      for (; s < spp; ++s) {
        float w;
        if (use_weights) {
          w = wrow[s];
        } else {
          MpFixed2 q = mp_sample_position(qx, qy, s, spp, f, offsets);
          float dx = (float)q.x / (float)MP_SUBPIXEL_ONE - cx, dy = (float)q.y / (float)MP_SUBPIXEL_ONE - cy;
          w = mp_filter_weight(filter_type, dx, dy, filter_width);
        }
        if (w <= 0.0f) continue;
        ulong index = q * (ulong)spp + (ulong)s;
        wsum += w;
        if (keys[index] == (ulong)0xffffffffffffffffUL) continue;
        float3 col = mp_load_color(colors, q, s, spp, f);
        sum += w * (float4)(col, f.holdout_covers || !f.holdouts ? 1.0f : 1.0f - mp_unpack_holdout(col.z));
      }
    }
#define MP_SUM8(v) ((((v).s0 + (v).s1) + ((v).s2 + (v).s3)) + (((v).s4 + (v).s5) + ((v).s6 + (v).s7)))
  if (lanes && spp >= 8) {
    wsum += MP_SUM8(w8);
    sum += (float4)(MP_SUM8(r8), MP_SUM8(g8), MP_SUM8(b8), MP_SUM8(a8));
  }
#undef MP_SUM8
  mp_resolve_write(MP_RESOLVE_PASS, px, py, sum, wsum);
}

/* Writes pixel (px, py)'s filtered colour and alpha, and its Depth and
 * Normal (from its own samples) when want_passes. */
inline void mp_resolve_write(MP_RESOLVE_ARGS, int px, int py, float4 sum, float wsum) {
  int spp = f.spp_x * f.spp_y;
  ulong pixel = (ulong)py * (ulong)f.width + (ulong)px;
  ulong out = (ulong)(py + origin.y) * (ulong)out_width + (ulong)(px + origin.x);
  rgba[out] = wsum > 0.0f ? sum / wsum : (float4)(0.0f);
  if (!want_passes) return;

  float zmin = MP_NO_DEPTH;
  float3 nsum = (float3)(0.0f);
  for (int s = 0; s < spp; ++s) {
    ulong key = keys[pixel * (ulong)spp + (ulong)s];
    if (key == (ulong)0xffffffffffffffffUL) continue;
    zmin = fmin(zmin, as_float((uint)(key >> 32)));
    if (!f.normal_pass) continue; /* samples hold no normals: the Normal pass is off */
    float3 n = mp_decode_normal(normals[pixel * (ulong)spp + (ulong)s]);
    nsum += (float3)(dot(cam_to_world_x.xyz, n), dot(cam_to_world_y.xyz, n), dot(cam_to_world_z.xyz, n));
  }
  depth[out] = zmin;
  vstore3(nsum / (float)spp, out, normal_out);
}

__kernel void resolve_pixels(MP_RESOLVE_ARGS) { mp_resolve(MP_RESOLVE_PASS, 0); }

/* Planar sample colors (the tile sampler's). */
__kernel void resolve_pixels_planar(MP_RESOLVE_ARGS) { mp_resolve(MP_RESOLVE_PASS, 1); }

/* The resolve by tiles (RenderSettings::resolver, made for GPUs): a
 * work-group of MP_RESOLVE_TILE x MP_RESOLVE_TILE pixels first loads the
 * samples of its pixels and of the filter's reach around them into local
 * memory, each as what the filter sums of it (colour, and the alpha it
 * shows; zero where nothing covers it), then each pixel sums its
 * neighbourhood from there. A sample is read from device memory once a tile
 * instead of once for every pixel whose filter reaches it ((2 reach + 1)^2
 * times), and neighbouring work-items read neighbouring samples. `records`
 * holds (MP_RESOLVE_TILE + 2 reach)^2 spp float4s; `weights` must be given
 * (use_weights). The sums are those of mp_resolve in another order. */
__kernel __attribute__((reqd_work_group_size(MP_RESOLVE_TILE, MP_RESOLVE_TILE, 1))) void resolve_pixels_tiled(
    MP_RESOLVE_ARGS, __local float4* records) {
  int spp = f.spp_x * f.spp_y;
  int reach = mp_filter_reach(filter_width);
  int side = MP_RESOLVE_TILE + 2 * reach, fside = 2 * reach + 1; /* the tile's and the filter's */
  int x0 = region.x + (int)get_group_id(0) * MP_RESOLVE_TILE - reach;
  int y0 = region.y + (int)get_group_id(1) * MP_RESOLVE_TILE - reach;
  int total = side * side * spp;
  for (int j = (int)(get_local_id(1) * MP_RESOLVE_TILE + get_local_id(0)); j < total;
       j += MP_RESOLVE_TILE * MP_RESOLVE_TILE) {
    int p = j / spp, s = j - p * spp;
    int qx = x0 + p % side, qy = y0 + p / side;
    float4 r = (float4)(0.0f);
    if (qx >= 0 && qy >= 0 && qx < f.width && qy < f.height) {
      ulong q = (ulong)qy * (ulong)f.width + (ulong)qx;
      if (keys[q * (ulong)spp + (ulong)s] != (ulong)0xffffffffffffffffUL) {
        float3 col = mp_load_color(colors, q, s, spp, f);
        r = (float4)(col, f.holdout_covers || !f.holdouts ? 1.0f : 1.0f - mp_unpack_holdout(col.z));
      }
    }
    records[j] = r;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  int px = region.x + (int)get_global_id(0), py = region.y + (int)get_global_id(1);
  if (px >= region.z || py >= region.w) return;
  int tile = ((py + f.crop_y0) & (MP_SAMPLE_TILE - 1)) * MP_SAMPLE_TILE + ((px + f.crop_x0) & (MP_SAMPLE_TILE - 1));
  float4 sum = (float4)(0.0f);
  float wsum = 0.0f;
  for (int qy = max(py - reach, 0); qy <= min(py + reach, f.height - 1); ++qy)
    for (int qx = max(px - reach, 0); qx <= min(px + reach, f.width - 1); ++qx) {
      __global const float* wrow = weights + ((ulong)tile * (ulong)(fside * fside) +
                                              (ulong)((qy - py + reach) * fside + (qx - px + reach))) * (ulong)spp;
      __local const float4* rec = records + ((qy - y0) * side + (qx - x0)) * spp;
      for (int s = 0; s < spp; ++s) {
        float w = wrow[s];
        if (w <= 0.0f) continue;
        wsum += w;
        sum += w * rec[s];
      }
    }
  mp_resolve_write(MP_RESOLVE_PASS, px, py, sum, wsum);
}

// The image as half floats for a read-back in half the bytes
// (RenderSettings::read_back, ReadBack::Half): rounded to nearest even, as
// the host's own conversion of a float image to half would round.
__kernel void image_to_half(__global const float4* rgba, __global half* out, uint pixels) {
  const uint i = get_global_id(0);
  if (i < pixels) vstore_half4_rte(rgba[i], i, out);
}
