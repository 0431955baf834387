/* Shadow maps (mp_shadow.h): marking the pages the camera needs, clearing
 * pages before they are rendered, and rasterising the lights' views into
 * their pages (depth only). The views themselves go through the same bound
 * & split, dicing and displacement as the camera's (bound_split.cl,
 * dice.cl, material programs), several views in one pass. */
#include "mp_compat.h"
#include "mp_patch.h"
#include "mp_types.h"
#include "mp_hash.h"
#include "mp_patch_eval.h"
#include "mp_surface.h"
#include "mp_raster.h"
#include "mp_grid.h"
#include "mp_bound.h"
#include "mp_shadow.h"

/* Texels of margin around a receiver's box when marking: soft shadows'
 * filters read up to MP_SHADOW_SEARCH_TEXELS from a receiver, hard shadows'
 * the bilinear texels around it; a texel more for rounding. */
MP_INLINE float mp_mark_margin(const MP_GLOBAL DeviceShadow* sh) {
  return sh->shape == MP_SHADOW_SHAPE_POINT ? 2.0f : MP_SHADOW_SEARCH_TEXELS + 2.0f;
}

inline void mp_mark_rect(__global uchar* requests, uint table, int side, int origin_x, int origin_y, float x0, float y0,
                         float x1, float y1) {
  float last = (float)(side * MP_PAGE_SIZE - 1);
  if (x1 < 0.0f || y1 < 0.0f || x0 > last || y0 > last) return;
  int px0 = (int)fmax(x0, 0.0f) >> 7, px1 = (int)fmin(x1, last) >> 7;
  int py0 = (int)fmax(y0, 0.0f) >> 7, py1 = (int)fmin(y1, last) >> 7;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      int sx = (px + origin_x) & (side - 1), sy = (py + origin_y) & (side - 1);
      requests[table + (uint)(sy * side + sx)] = (uchar)1;
    }
}

/* A sun's pages under the light-space box [lo, hi] of receivers whose
 * pixel footprints lie in [s0, s1]. */
inline void mp_mark_sun(__global const DeviceShadow* sh, __global const DeviceShadowLevel* levels, float3 lo, float3 hi,
                        float s0, float s1, __global uchar* requests) {
  int l0 = mp_sun_level_for(s0) + sh->level_bias, l1 = mp_sun_level_for(s1) + sh->level_bias;
  if (sh->shape != MP_SHADOW_SHAPE_POINT && sh->size[0] > 0.0f) {
    /* Soft shadows read coarser levels, up to the blocker search's. */
    float search = sh->size[0] * fmax(sh->z_top - lo.z, 0.0f);
    l1 = max(l1, mp_ceil_log2(fmax(search / MP_SHADOW_SEARCH_TEXELS, 1e-30f)));
  }
  int count = (int)sh->levels;
  int i0 = clamp(l0 - sh->level0, 0, count - 1), i1 = clamp(l1 - sh->level0, 0, count - 1);
  float margin = mp_mark_margin(sh);
  for (int i = i0; i <= i1; ++i) {
    __global const DeviceShadowLevel* lv = levels + sh->level_records + (uint)i;
    float k = 1.0f / lv->texel;
    mp_mark_rect(requests, lv->page_table, MP_MAP_PAGES, lv->origin_x, lv->origin_y,
                 (lo.x + lv->offset[0]) * k - margin, (lo.y + lv->offset[1]) * k - margin,
                 (hi.x + lv->offset[0]) * k + margin, (hi.y + lv->offset[1]) * k + margin);
  }
}

/* A local light's cube pages under the light-space box [lo, hi]. */
inline void mp_mark_cube(__global const DeviceShadow* sh, float3 lo, float3 hi, float s0, float s1,
                         __global uchar* requests) {
  float rmax = length(fmax(fabs(lo), fabs(hi)));
  /* per axis, the box's distance from the light; a face depth is at least r / sqrt(3) */
  float rmin = fmax(length(fmax(fmax(lo, -hi), MP_F3(0.0f, 0.0f, 0.0f))) * 0.57735027f, 1e-20f);
  int m0 = mp_cube_mip_for(s0, rmax) + sh->level_bias, m1 = mp_cube_mip_for(s1, rmin) + sh->level_bias;
  if (sh->shape != MP_SHADOW_SHAPE_POINT) {
    float search = mp_light_shape_radius(sh) * MP_SHADOW_SEARCH_SCALE;
    m1 = max(m1, mp_ceil_log2(fmax(search / MP_SHADOW_SEARCH_TEXELS * (float)(MP_MAP_TEXELS / 2) / rmin, 1e-30f)));
  }
  m0 = clamp(m0, 0, MP_CUBE_MIPS - 1);
  m1 = clamp(m1, 0, MP_CUBE_MIPS - 1);
  for (int m = m0; m <= m1; ++m) {
    float texels = (float)mp_cube_mip_texels(m);
    /* The margin as scene units at the box's far side. */
    float margin = mp_mark_margin(sh) * rmax * 2.0f / texels;
    float3 e = MP_F3(margin, margin, margin);
    for (int face = 0; face < 6; ++face) {
      float x0, y0, x1, y1;
      if (!mp_cube_face_box(face, lo - e, hi + e, texels, &x0, &y0, &x1, &y1)) continue;
      mp_mark_rect(requests, sh->page_table + (uint)face * MP_CUBE_FACE_ENTRIES + mp_cube_mip_entries(m),
                   MP_MAP_PAGES >> m, 0, 0, x0, y0, x1, y1);
    }
  }
}

/* Marks, for every light with shadow maps, the pages the receivers of a
 * coarse camera pass need (one work-item per grid vertex, displaced): at
 * the level (mip) whose texels are no larger than the vertex's pixel
 * footprint (mp_shadow.h), under a box around the vertex reaching its
 * neighbours (`reach` pixels). Soft shadows also mark the coarser levels
 * their filters read. */
__kernel void mark_shadow_pages(__global const SubPatch* diceable, uint count, __global const uint* vertex_offsets,
                                FrameParams f, __global const float4* grid_p, __global const DeviceShadow* shadows,
                                __global const DeviceShadowLevel* levels, uint light_count,
                                __global uchar* requests, float reach) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  float3 p = grid_p[index].xyz;
  float d = -p.z;
  if (!f.ortho && !(d > 0.0f)) return;
  float s = mp_pixel_footprint(d, f);
  float r = reach * s;
  for (uint l = 0; l < light_count; ++l) {
    __global const DeviceShadow* sh = shadows + l;
    if (sh->kind == MP_SHADOW_NONE) continue;
    float3 q = mp_xform_point(sh->to_light, p);
    float3 lo = q - MP_F3(r, r, r), hi = q + MP_F3(r, r, r);
    if (sh->kind == MP_SHADOW_SUN) {
      mp_mark_sun(sh, levels, lo, hi, s, s, requests);
      continue;
    }
    /* Receivers the light cannot reach need no pages: behind an area
     * light, or outside a spot's cone (by the box's bounding sphere: its
     * angle from the axis, less its angular radius, exceeds the cone's). */
    if (sh->one_sided && lo.z >= 0.0f) continue;
    if (sh->cone_cos > -1.5f) {
      float dist = length(q), rad = 1.7320508f * r;
      if (dist > rad) {
        float cos_axis = -q.z / dist, sin_axis = sqrt(fmax(1.0f - cos_axis * cos_axis, 0.0f));
        float sin_spread = rad / dist, cos_spread = sqrt(fmax(1.0f - sin_spread * sin_spread, 0.0f));
        if (cos_axis < cos_spread && cos_axis * cos_spread + sin_axis * sin_spread < sh->cone_cos) continue;
      }
    }
    mp_mark_cube(sh, lo, hi, s, s, requests);
  }
}

/* Sets every texel of the listed physical pages to "nothing here". */
__kernel void clear_shadow_pages(__global const uint* pages, uint texel_count, __global uint* pool) {
  uint i = get_global_id(0);
  if (i >= texel_count) return;
  pool[(ulong)pages[i / MP_PAGE_TEXELS] * MP_PAGE_TEXELS + (ulong)(i % MP_PAGE_TEXELS)] = MP_SHADOW_EMPTY;
}

/* Raster position (fixed point) and depth of a camera-space point in view v. */
inline int mp_shadow_vertex(float4 p, FrameParams v, MpFixed2* r, float* inv_d) {
  float3 q = mp_to_view(p.xyz, v);
  float d = -q.z;
  if (!v.ortho && !(d > 0.0f)) return 0;
  float inv = v.ortho ? 1.0f : 1.0f / d;
  float rx = v.ax * q.x * inv + v.bx, ry = v.ay * q.y * inv + v.by;
  if (!(fabs(rx) < MP_RASTER_GUARD && fabs(ry) < MP_RASTER_GUARD)) return 0;
  r->x = mp_to_fixed(rx);
  r->y = mp_to_fixed(ry);
  *inv_d = v.ortho ? d : inv; /* interpolated linearly in raster space */
  return 1;
}

/* One work-item per micropolygon of grids [first, first + count) of a
 * shadow pass (the layout of sample.cl's sample_micropolygons): samples at
 * texel centres of the micropolygon's view, kept in the pages this frame
 * renders, with a 32-bit atomic minimum of the depth (positive floats order
 * as their bits do). Opacity below one keeps a matching fraction of texels,
 * as the camera's samples do. */
__kernel __attribute__((reqd_work_group_size(64, 1, 1)))
void shadow_sample(__global const SubPatch* diceable, uint first, uint count, __global const uint* offsets, uint base,
                   uint total, __global const uint* patch_info, __global const DeviceMaterial* materials, FrameParams f,
                   __global const FrameParams* views, __global const float4* grid_p, __global const float4* grid_c,
                   __global const uint* page_table, volatile __global uint* pool) {
  uint gid = get_global_id(0);
  if (gid >= total || count == 0u) return;
  uint slot = first + mp_find_grid(offsets + first, count, base + gid);
  uint m = base + gid - offsets[slot];
  SubPatch sp = diceable[slot];
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  uint q[4];
  if (!mp_grid_micropolygon(&g, m, q)) return;
  FrameParams v = views[MP_INFO_VIEW(sp.info)];
  uint stride = (uint)f.max_grid + 1u;
  ulong grid_base = (ulong)slot * stride * stride;
  MpFixed2 r[4];
  float w[4];
  for (int k = 0; k < 4; ++k)
    if (!mp_shadow_vertex(grid_p[grid_base + q[k]], v, &r[k], &w[k])) return;
  MpEdgeTriangle tris[2];
  tris[0] = mp_edge_triangle(r[0], r[1], r[2]);
  tris[1] = mp_edge_triangle(r[0], r[2], r[3]);
  float tw[2][3] = {{w[0], tris[0].swapped ? w[2] : w[1], tris[0].swapped ? w[1] : w[2]},
                    {w[0], tris[1].swapped ? w[3] : w[2], tris[1].swapped ? w[2] : w[3]}};
  long xmin = min(min(r[0].x, r[1].x), min(r[2].x, r[3].x)), xmax = max(max(r[0].x, r[1].x), max(r[2].x, r[3].x));
  long ymin = min(min(r[0].y, r[1].y), min(r[2].y, r[3].y)), ymax = max(max(r[0].y, r[1].y), max(r[2].y, r[3].y));
  const long centre = MP_SUBPIXEL_ONE / 2;
  int px0 = (int)max((xmin - centre + MP_SUBPIXEL_ONE - 1) >> MP_SUBPIXEL_BITS, (long)0);
  int px1 = (int)min((xmax - centre) >> MP_SUBPIXEL_BITS, (long)v.width - 1);
  int py0 = (int)max((ymin - centre + MP_SUBPIXEL_ONE - 1) >> MP_SUBPIXEL_BITS, (long)0);
  int py1 = (int)min((ymax - centre) >> MP_SUBPIXEL_BITS, (long)v.height - 1);
  if (px0 > px1 || py0 > py1) return;
  /* Opacity: the material's, or per vertex where its node program computes
   * one (material_program.cl, run for alpha only in shadow passes). */
  __global const DeviceMaterial* mat = materials + patch_info[4 * (ulong)sp.patch + 1];
  float opacity = mat->program[3] > 0.0f ? grid_c[grid_base + q[0]].w : mat->opacity[3];
  uint mp_id = 0u;
  if (opacity < 1.0f) {
    mp_id = mp_hash32(sp.patch);
    for (int k = 0; k < 8; ++k) mp_id = mp_hash_combine(mp_id, as_uint(sp.corner[k]));
    mp_id = mp_hash_combine(mp_id, m);
  }
  int side = v.page_side;
  /* Most micropolygons lie within one page: one table lookup for all. */
  int one_page = (px0 >> 7) == (px1 >> 7) && (py0 >> 7) == (py1 >> 7);
  uint e = 0u;
  if (one_page) {
    int sx = ((px0 >> 7) + v.page_origin_x) & (side - 1), sy = ((py0 >> 7) + v.page_origin_y) & (side - 1);
    e = page_table[v.page_table + (uint)(sy * side + sx)];
    if (!(e & MP_PAGE_RENDER)) return;
  }
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      if (!one_page) {
        int sx = ((px >> 7) + v.page_origin_x) & (side - 1), sy = ((py >> 7) + v.page_origin_y) & (side - 1);
        e = page_table[v.page_table + (uint)(sy * side + sx)];
        if (!(e & MP_PAGE_RENDER)) continue;
      }
      MpFixed2 s;
      s.x = (long)px * MP_SUBPIXEL_ONE + centre;
      s.y = (long)py * MP_SUBPIXEL_ONE + centre;
      float la, lb, lc;
      int t = 0;
      if (!mp_edge_triangle_covers(&tris[0], s, &la, &lb, &lc)) {
        t = 1;
        if (!mp_edge_triangle_covers(&tris[1], s, &la, &lb, &lc)) continue;
      }
      float iw = la * tw[t][0] + lb * tw[t][1] + lc * tw[t][2];
      float d = v.ortho ? iw : 1.0f / iw;
      if (!(d >= v.clip_near && d <= v.clip_far)) continue;
      uint texel = (uint)((py & 127) * MP_PAGE_SIZE + (px & 127));
      if (opacity < 1.0f && mp_hash_unit(mp_hash_combine(mp_id, (uint)(py * v.width + px))) >= opacity) continue;
      atomic_min(&pool[(ulong)MP_PAGE_PHYSICAL(e) * MP_PAGE_TEXELS + texel], as_uint(d));
    }
}
