/* Shadow maps (mp_shadow.h): marking the pages the camera needs, clearing
 * pages before they are rendered, and rasterising the lights' views into
 * their pages (depth only). The views themselves go through the same bound
 * & split, dicing and displacement as the camera's (bound_split.cl,
 * dice.cl, material programs), several views in one pass. */
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "core/mp_hash.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "stages/mp_raster.h"
#include "geometry/mp_grid.h"
#include "geometry/mp_bound.h"
#include "shadow/mp_shadow.h"
#include "stages/mp_occlusion.h"
#include "core/mp_scene_data.h"

/* Texels of margin around a receiver's box when marking: soft shadows'
 * filters read up to MP_SHADOW_SEARCH_TEXELS from a receiver, hard shadows'
 * the bilinear texels around it; a texel more for rounding. */
MP_INLINE float mp_mark_margin(const MP_GLOBAL DeviceShadow* sh) {
  return sh->shape == MP_SHADOW_SHAPE_POINT ? 2.0f : MP_SHADOW_SEARCH_TEXELS + 2.0f;
}

/* Per page-table entry, `requests` says whether a receiver asked for the
 * page, and `caps` holds the farthest depth in the map's view (a positive
 * float's bits) of the receivers that asked for it or may ask for it in the
 * soft marking: whatever lies beyond shadows none of them, and the lights'
 * views cull it (shadow_page_farthest). Where `request` is 0 the rectangle's
 * caps grow but nothing is asked for. */
inline void mp_mark_rect(__global uchar* requests, volatile __global uint* caps, uint table, int side, int origin_x,
                         int origin_y, float x0, float y0, float x1, float y1, uint far_bits, int request) {
  float last = (float)(side * MP_PAGE_SIZE - 1);
  if (x1 < 0.0f || y1 < 0.0f || x0 > last || y0 > last) return;
  int px0 = (int)fmax(x0, 0.0f) >> 7, px1 = (int)fmin(x1, last) >> 7;
  int py0 = (int)fmax(y0, 0.0f) >> 7, py1 = (int)fmin(y1, last) >> 7;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      int sx = (px + origin_x) & (side - 1), sy = (py + origin_y) & (side - 1);
      uint e = table + (uint)(sy * side + sx);
      if (request) requests[e] = (uchar)1;
      if (caps[e] < far_bits) atomic_max(caps + e, far_bits);
    }
}

/* The nearest and farthest face depth a light-space box can have (a face
 * depth is at least a point's distance over sqrt(3)). */
inline void mp_box_depths(float3 lo, float3 hi, float* near_depth, float* far_depth) {
  *far_depth = length(fmax(fabs(lo), fabs(hi)));
  *near_depth = fmax(length(fmax(fmax(lo, -hi), MP_F3(0.0f, 0.0f, 0.0f))) * 0.57735027f, 1e-20f);
}

/* The levels (sun: indices from level0; cube: mips) that receivers in the
 * light-space box [lo, hi] with pixel footprint s read for hard shadows. */
inline void mp_base_levels(__global const DeviceShadow* sh, float3 lo, float3 hi, float s, int* first, int* last) {
  if (sh->kind == MP_SHADOW_SUN) {
    *first = *last = mp_sun_level_for(s) + sh->level_bias - sh->level0;
    return;
  }
  float dn, df;
  mp_box_depths(lo, hi, &dn, &df);
  *first = mp_cube_mip_for(s, df) + sh->level_bias;
  *last = mp_cube_mip_for(s, dn) + sh->level_bias;
}

/* The levels the first round of a soft light's blocker search reads there
 * (mp_blocker_round), no finer than the base levels. */
inline void mp_probe_levels(__global const DeviceShadow* sh, float3 lo, float3 hi, int base_first, int base_last,
                            int* first, int* last) {
  float radius = mp_light_shape_radius(sh);
  int a, b;
  if (sh->kind == MP_SHADOW_SUN) {
    float s_near = fmax(sh->z_top - hi.z, 0.0f), s_far = fmax(sh->z_top - lo.z, 0.0f);
    a = mp_ceil_log2(fmax(radius * s_near / MP_SHADOW_SEARCH_TEXELS, 1e-30f)) - sh->level0;
    b = mp_ceil_log2(fmax(radius * s_far / MP_SHADOW_SEARCH_TEXELS, 1e-30f)) - sh->level0;
  } else {
    float dn, df, texels = radius * MP_SHADOW_SEARCH_SCALE / MP_SHADOW_SEARCH_TEXELS * (float)(MP_MAP_TEXELS / 2);
    mp_box_depths(lo, hi, &dn, &df);
    a = mp_ceil_log2(fmax(texels / df, 1e-30f));
    b = mp_ceil_log2(fmax(texels / dn, 1e-30f));
  }
  *first = max(a, base_first);
  *last = max(b, base_last);
}

/* Marks the pages of levels [first, last] under the light-space box [lo,
 * hi], grown by the margin the light's filters need. */
inline void mp_mark_levels(__global const DeviceShadow* sh, __global const DeviceShadowLevel* levels, float3 lo,
                           float3 hi, int first, int last, __global uchar* requests, volatile __global uint* caps,
                           int request) {
  int count = mp_shadow_level_count(sh);
  first = clamp(first, 0, count - 1);
  last = clamp(last, 0, count - 1);
  float margin = mp_mark_margin(sh);
  /* The receivers' farthest depth: the box's (a sun's depth runs down from
   * z_top; a face's is the light-space coordinate along its axis). The box
   * reaches a coarse micropolygon's edge around its vertex, so it holds the
   * finer surface of the micropolygons around the vertex nearer to it than
   * to their other corners. */
  if (sh->kind == MP_SHADOW_SUN) {
    uint far_bits = as_uint(fmax(sh->z_top - lo.z, 1e-30f));
    for (int i = first; i <= last; ++i) {
      __global const DeviceShadowLevel* lv = levels + sh->level_records + (uint)i;
      float k = 1.0f / lv->texel;
      mp_mark_rect(requests, caps, lv->page_table, MP_MAP_PAGES, lv->origin_x, lv->origin_y,
                   (lo.x + lv->offset[0]) * k - margin, (lo.y + lv->offset[1]) * k - margin,
                   (hi.x + lv->offset[0]) * k + margin, (hi.y + lv->offset[1]) * k + margin, far_bits, request);
    }
    return;
  }
  float dn, df;
  mp_box_depths(lo, hi, &dn, &df);
  float radius = mp_light_shape_radius(sh);
  for (int m = first; m <= last; ++m) {
    float texels = (float)mp_cube_mip_texels(m);
    /* The margin as scene units at the box's far side. */
    float grow = margin * df * 2.0f / texels;
    float3 e = MP_F3(grow, grow, grow);
    for (int face = 0; face < 6; ++face) {
      float x0, y0, x1, y1;
      if (!mp_cube_face_box(face, lo - e, hi + e, texels, &x0, &y0, &x1, &y1)) continue;
      /* The face's depth of the box's far side; a segment from a receiver
       * to the light's shape reaches no deeper than the receiver or the
       * shape's own extent. */
      float far_depth = -fmin(mp_cube_face_view(face, lo).z, mp_cube_face_view(face, hi).z);
      uint far_bits = as_uint(fmax(far_depth, fmax(radius, 1e-30f)));
      mp_mark_rect(requests, caps, sh->page_table + (uint)face * MP_CUBE_FACE_ENTRIES + mp_cube_mip_entries(m),
                   MP_MAP_PAGES >> m, 0, 0, x0, y0, x1, y1, far_bits, request);
    }
  }
}

/* Whether receivers in the light-space box [lo, hi] can get light at all:
 * not behind an area light, nor (by the box's bounding sphere: its angle
 * from the axis, less its angular radius, exceeds the cone's) outside a
 * spot's cone. */
inline int mp_box_lit(__global const DeviceShadow* sh, float3 lo, float3 hi) {
  if (sh->one_sided && lo.z >= 0.0f) return 0;
  if (sh->cone_cos > -1.5f) {
    float3 c = 0.5f * (lo + hi);
    float dist = length(c), rad = 0.5f * length(hi - lo);
    if (dist > rad) {
      float cos_axis = -c.z / dist, sin_axis = sqrt(fmax(1.0f - cos_axis * cos_axis, 0.0f));
      float sin_spread = rad / dist, cos_spread = sqrt(fmax(1.0f - sin_spread * sin_spread, 0.0f));
      if (cos_axis < cos_spread && cos_axis * cos_spread + sin_axis * sin_spread < sh->cone_cos) return 0;
    }
  }
  return 1;
}

/* The grid vertex a marking work-item handles, its light-space box (reach
 * pixels wide around it) for light sh and its pixel footprint; 0 for a
 * vertex behind the camera or one the light cannot reach. */
inline int mp_marking_box(__global const DeviceShadow* sh, float3 p, FrameParams f, float reach, float3* q, float3* lo,
                          float3* hi, float* s) {
  float d = -p.z;
  if (!f.ortho && !(d > 0.0f)) return 0;
  *s = mp_pixel_footprint(d, f);
  float r = reach * *s;
  *q = mp_xform_point(sh->to_light, p);
  *lo = *q - MP_F3(r, r, r);
  *hi = *q + MP_F3(r, r, r);
  return sh->kind == MP_SHADOW_SUN || mp_box_lit(sh, *lo, *hi);
}

/* Marks, for every light with shadow maps, the pages around a camera-space
 * receiver p: the level (mip) whose texels are no larger than its pixel
 * footprint (mp_shadow.h) for hard shadows, and the first blocker search
 * round's levels for soft ones, under a box around it reaching its
 * neighbours (`reach` pixels). */
inline void mp_mark_vertex(float3 p, FrameParams f, __global const DeviceShadow* shadows,
                           __global const DeviceShadowLevel* levels, uint shadow_count, __global uchar* requests,
                           volatile __global uint* caps, float reach, uint soft) {
  for (uint l = 0; l < shadow_count; ++l) {
    __global const DeviceShadow* sh = shadows + l;
    if (sh->kind == MP_SHADOW_NONE) continue;
    float3 q, lo, hi;
    float s;
    if (!mp_marking_box(sh, p, f, reach, &q, &lo, &hi, &s)) continue;
    int first, last;
    mp_base_levels(sh, lo, hi, s, &first, &last);
    const int base_first = first;
    if (sh->shape != MP_SHADOW_SHAPE_POINT) mp_probe_levels(sh, lo, hi, first, last, &first, &last);
    mp_mark_levels(sh, levels, lo, hi, first, last, requests, caps, 1);
    /* The soft marking (`soft`) may ask for any level from the base one on,
     * for this receiver's box (mp_mark_soft_vertex): those caps grow now, so
     * that no page rendered before it is rendered again for it. */
    if (sh->shape != MP_SHADOW_SHAPE_POINT && soft)
      mp_mark_levels(sh, levels, lo, hi, base_first, mp_shadow_level_count(sh) - 1, requests, caps, 0);
  }
}

/* The camera's coarse depth (marking_depth.h): one work-item per
 * micropolygon of a coarse camera batch. A micropolygon of an opaque
 * material writes, at every level-0 cell centre of `o` it covers, its
 * farthest corner's depth plus a sixteenth of its longest edge, with a
 * 32-bit atomic minimum (positive floats order as their bits do). The
 * margin stands for the finer surface that the flat coarse micropolygon cuts
 * across (the chord of a surface curving away from the camera lies in front
 * of it): an arc of radius R bulges L^2 / 8R beyond its chord L, at most
 * L / 16 wherever a coarse micropolygon turns through less than about 30
 * degrees, so only what lies beyond counts as hidden. Materials with alpha or
 * opacity below one hide nothing here: what shows through their holes needs
 * its pages. */
__kernel __attribute__((reqd_work_group_size(64, 1, 1)))
void marking_depth(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, __global const uint* offsets,
                   uint total, FrameParams f, __global const float4* grid_p, OcclusionParams o,
                   volatile __global uint* depth) {
  uint gid = get_global_id(0);
  if (gid >= total || count == 0u) return;
  uint first = offsets[0];
  uint slot = mp_find_grid(offsets, count, first + gid);
  uint m = first + gid - offsets[slot];
  SubPatch sp = diceable[slot];
  if (!mp_material_opaque(materials, patch_info, sp.patch)) return;
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  uint q[4];
  if (!mp_grid_micropolygon(&g, m, q)) return;
  uint stride = (uint)f.max_grid + 1u;
  ulong grid_base = (ulong)slot * stride * stride;
  float3 v[4];
  float2 r[4];
  float far_depth = 0.0f;
  for (int k = 0; k < 4; ++k) {
    v[k] = mp_to_view(grid_p[grid_base + q[k]].xyz, f);
    /* Nearer than the clip range, it is not drawn and hides nothing. */
    if (!mp_view_point_usable(v[k], f) || !(-v[k].z >= f.clip_near)) return;
    r[k] = mp_project_view(v[k], f);
    far_depth = fmax(far_depth, -v[k].z);
  }
  float edge = 0.0f;
  for (int k = 0; k < 4; ++k) edge = fmax(edge, length(v[(k + 1) & 3] - v[k]));
  uint bits = as_uint(far_depth + edge * (1.0f / 16.0f));
  float cell = (float)(1 << o.cell_shift), half_cell = 0.5f * cell;
  float xmin = fmin(fmin(r[0].x, r[1].x), fmin(r[2].x, r[3].x)), xmax = fmax(fmax(r[0].x, r[1].x), fmax(r[2].x, r[3].x));
  float ymin = fmin(fmin(r[0].y, r[1].y), fmin(r[2].y, r[3].y)), ymax = fmax(fmax(r[0].y, r[1].y), fmax(r[2].y, r[3].y));
  if (!(xmax >= 0.0f && ymax >= 0.0f && xmin <= (float)f.width && ymin <= (float)f.height)) return;
  int cx0 = max((int)ceil((fmax(xmin, -cell) - half_cell) / cell), 0);
  int cx1 = min((int)floor((fmin(xmax, (float)f.width + cell) - half_cell) / cell), o.base_w - 1);
  int cy0 = max((int)ceil((fmax(ymin, -cell) - half_cell) / cell), 0);
  int cy1 = min((int)floor((fmin(ymax, (float)f.height + cell) - half_cell) / cell), o.base_h - 1);
  for (int cy = cy0; cy <= cy1; ++cy)
    for (int cx = cx0; cx <= cx1; ++cx) {
      float2 c = MP_F2((float)cx * cell + half_cell, (float)cy * cell + half_cell);
      /* Inside either triangle (0, 1, 2), (0, 2, 3), whichever way round,
       * or within a thousandth of a pixel of it: a centre on the edge two
       * triangles share must not fall between them by rounding. */
      int inside = 0;
      for (int t = 0; t < 2 && !inside; ++t) {
        float2 v3[3] = {r[0], r[t + 1], r[t + 2]};
        int pos = 1, neg = 1;
        for (int k = 0; k < 3; ++k) {
          float2 a = v3[k], b = v3[k == 2 ? 0 : k + 1];
          float e = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
          float slack = 1e-3f * (fabs(b.x - a.x) + fabs(b.y - a.y));
          pos = pos && e >= -slack;
          neg = neg && e <= slack;
        }
        inside = pos || neg;
      }
      if (inside) atomic_min(depth + (uint)(cy * o.base_w + cx), bits);
    }
}

/* Whether a marking vertex at camera-space p may be seen by the camera:
 * unless the coarse depth (marking_depth) holds something nearer at every
 * cell centre within a cell of it. A vertex of a seen surface finds its own
 * micropolygons there (their depth with its margin is at least its own); one
 * beside a silhouette finds the farther side. A vertex outside the frame
 * matters only within its box's reach (`reach` pixels) of the frame, and is
 * tested against the frame's edge there; vertices with no depth to test
 * against (o.levels 0, or at the eye) count as seen. */
inline int mp_marking_seen(float3 p, FrameParams f, __global const uint* depth, OcclusionParams o, float reach) {
  if (o.levels <= 0) return 1;
  float3 v = mp_to_view(p, f);
  if (!mp_view_point_usable(v, f)) return 1;
  float2 r = mp_project_view(v, f);
  if (!(r.x >= -reach && r.y >= -reach && r.x <= (float)f.width + reach && r.y <= (float)f.height + reach)) return 0;
  float cell = (float)(1 << o.cell_shift);
  int cx = clamp((int)floor(r.x / cell), 0, o.base_w - 1), cy = clamp((int)floor(r.y / cell), 0, o.base_h - 1);
  uint near_bits = as_uint(-v.z * (1.0f - 1.0f / 65536.0f));
  for (int y = max(cy - 1, 0); y <= min(cy + 1, o.base_h - 1); ++y)
    for (int x = max(cx - 1, 0); x <= min(cx + 1, o.base_w - 1); ++x)
      if (depth[y * o.base_w + x] >= near_bits) return 1;
  return 0;
}

/* The camera's roots, seen ones first (marking_depth.h): at each position
 * i of the camera's near-to-far order, 0 where that patch's box lies inside
 * the frame but behind the marking's complete coarse depth everywhere, else
 * 1 (boxes outside the frame count as seen: their first test culls them,
 * wherever they come). Only an order: the camera culls against its own
 * samples, never against this depth. */
__kernel void marking_roots_seen(MP_SCENE_PARAMS __global const uint* order, uint n, FrameParams f,
                                 __global const uint* depth, OcclusionParams o, __global uint* seen) {
  uint i = get_global_id(0);
  if (i > n) return;
  if (i == n) { /* one past the end: 0, so that the scan leaves the total there */
    seen[n] = 0u;
    return;
  }
  uint p = order[i];
  float3 lo = patch_bounds[2 * (ulong)p].xyz, hi = patch_bounds[2 * (ulong)p + 1].xyz;
  MpBound b = mp_bound_boxes(&lo, &hi, 1, f);
  seen[i] = mp_bound_culled(b, &lo, &hi, 1, f, 0, 1) ||
                    !mp_occluded(depth, o, f, b.xmin, b.ymin, b.xmax, b.ymax, b.dmin, (float4)(0.0f))
                ? 1u
                : 0u;
}

/* The order again, the seen roots first and then the rest, each in the
 * order they had: `at` is the exclusive prefix sum of marking_roots_seen's
 * flags (n + 1 of them, the total last). */
__kernel void marking_roots_partition(__global const uint* order, uint n, __global const uint* at,
                                      __global uint* out) {
  uint i = get_global_id(0);
  if (i >= n) return;
  out[at[i + 1u] > at[i] ? at[i] : at[n] + (i - at[i])] = order[i];
}

/* The first marking from a coarse camera batch's grids (one work-item per
 * grid vertex, displaced): the vertex is kept at keep_base + its index
 * where `keep` is set, three floats for its position and, with `keep_n`,
 * three for its normal (an x that is NaN: no vertex there), for the marking
 * that follows the coarse depth (mark_kept_shadow_pages) and the soft one;
 * where `mark` is set, it marks its pages now, if the coarse depth (`o`
 * levels above 0) says it may be seen. */
__kernel void mark_shadow_pages(__global const SubPatch* diceable, uint count, __global const uint* vertex_offsets,
                                uint vertex_total, FrameParams f, __global const float4* grid_p,
                                __global const float4* grid_n, __global const DeviceShadow* shadows,
                                __global const DeviceShadowLevel* levels, uint shadow_count,
                                __global uchar* requests, volatile __global uint* caps, float reach, uint soft,
                                uint mark, uint keep, uint keep_n, uint keep_base, __global float* kept_p,
                                __global float* kept_n, __global const uint* depth, OcclusionParams o) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  int valid = mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index);
  if (keep && gid < vertex_total) {
    vstore3(valid ? grid_p[index].xyz : (float3)(NAN, 0.0f, 0.0f), keep_base + gid, kept_p);
    if (keep_n) vstore3(valid ? grid_n[index].xyz : (float3)(0.0f), keep_base + gid, kept_n);
  }
  if (!valid || !mark) return;
  float3 p = grid_p[index].xyz;
  if (mp_marking_seen(p, f, depth, o, reach))
    mp_mark_vertex(p, f, shadows, levels, shadow_count, requests, caps, reach, soft);
}

/* The first marking from the kept vertices, once the coarse depth is
 * complete: only those the camera may see mark pages. */
__kernel void mark_kept_shadow_pages(__global const float* kept_p, uint kept, FrameParams f,
                                     __global const DeviceShadow* shadows, __global const DeviceShadowLevel* levels,
                                     uint shadow_count, __global uchar* requests, volatile __global uint* caps,
                                     float reach, uint soft, __global const uint* depth, OcclusionParams o) {
  uint gid = get_global_id(0);
  if (gid >= kept) return;
  float3 p = vload3(gid, kept_p);
  if (isnan(p.x) || !mp_marking_seen(p, f, depth, o, reach)) return;
  mp_mark_vertex(p, f, shadows, levels, shadow_count, requests, caps, reach, soft);
}

/* Second marking, for soft shadows, on the maps the first rendered (one
 * work-item per vertex the first kept that the camera may see): where a vertex's first search round
 * finds occluders, the levels the second round and the penumbra filter can
 * read there, from the nearest occluder's (the narrowest penumbra, the
 * finest level) to the coarsest; receivers that see no occluder read
 * nothing more. */
inline void mp_mark_soft_vertex(float3 p, float3 n, FrameParams f, __global const DeviceShadow* shadows,
                                __global const DeviceShadowLevel* levels, uint shadow_count,
                                __global const uint* pages, __global const uint* pool, __global uchar* requests,
                                volatile __global uint* caps, float reach) {
  MpShadowMaps maps = {shadows, levels, pages, pool};
  for (uint l = 0; l < shadow_count; ++l) {
    __global const DeviceShadow* sh = shadows + l;
    if (sh->kind == MP_SHADOW_NONE || sh->shape == MP_SHADOW_SHAPE_POINT) continue;
    float3 q, lo, hi;
    float s;
    if (!mp_marking_box(sh, p, f, reach, &q, &lo, &hi, &s)) continue;
    float3 nq = mp_xform_dir(sh->to_light, n);
    int base = mp_shadow_base_level(sh, q, s);
    MpLightShape shape = mp_light_shape(sh, q);
    uint plane_key = 0xffffffffu;
    MpReceiverPlane plane;
    float s1 = mp_first_search_scale(sh, q), found, sum, nearest;
    int count_levels = mp_shadow_level_count(sh);
    if (mp_blocker_round(&maps, sh, &shape, q, nq, mp_shadow_bias_texels(sh, q, nq), base, 0, s1, &plane_key, &plane,
                         &found, &sum, &nearest) >= count_levels ||
        !(found > 0.0f))
      continue;
    float radius = mp_light_shape_radius(sh);
    float s2 = fmin(s1, 2.0f * sum / found);
    int second = mp_shadow_level_for_size(sh, q, radius * s2, MP_SHADOW_SEARCH_TEXELS, base);
    int finest = (int)floor(mp_filter_level(sh, q, radius * nearest));
    int first, last;
    mp_base_levels(sh, lo, hi, s, &first, &last);
    mp_mark_levels(sh, levels, lo, hi, max(first, min(finest, second)), count_levels - 1, requests, caps, 1);
  }
}

__kernel void mark_soft_shadow_pages(__global const float* kept_p, __global const float* kept_n, uint kept,
                                     FrameParams f, __global const DeviceShadow* shadows,
                                     __global const DeviceShadowLevel* levels, uint shadow_count,
                                     __global const uint* pages, __global const uint* pool,
                                     __global uchar* requests, volatile __global uint* caps, float reach,
                                     __global const uint* depth, OcclusionParams o) {
  uint gid = get_global_id(0);
  if (gid >= kept) return;
  float3 p = vload3(gid, kept_p);
  if (isnan(p.x) || !mp_marking_seen(p, f, depth, o, reach)) return;
  mp_mark_soft_vertex(p, vload3(gid, kept_n), f, shadows, levels, shadow_count, pages, pool, requests, caps, reach);
}

/* The same, straight from a batch's grids: where the first marking's
 * vertices pass their share of the shadow budget, the second dices the view
 * again instead of keeping them. */
__kernel void mark_soft_shadow_pages_grid(__global const SubPatch* diceable, uint count,
                                          __global const uint* vertex_offsets, FrameParams f,
                                          __global const float4* grid_p, __global const float4* grid_n,
                                          __global const DeviceShadow* shadows,
                                          __global const DeviceShadowLevel* levels, uint shadow_count,
                                          __global const uint* pages, __global const uint* pool,
                                          __global uchar* requests, volatile __global uint* caps, float reach,
                                          __global const uint* depth, OcclusionParams o) {
  uint gid = get_global_id(0), i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, &sp, &i, &j, &uv, &index)) return;
  if (!mp_marking_seen(grid_p[index].xyz, f, depth, o, reach)) return;
  mp_mark_soft_vertex(grid_p[index].xyz, grid_n[index].xyz, f, shadows, levels, shadow_count, pages, pool, requests,
                      caps, reach);
}

/* The requested page-table entries, each with its cap, in no particular
 * order (the host sorts them): one work-item per entry. Past `capacity`
 * only the count grows, and the host reads the whole tables instead. */
__kernel void list_requests(__global const uchar* requests, __global const uint* caps, uint n,
                            volatile __global uint* count, __global uint2* list, uint capacity) {
  uint e = get_global_id(0);
  if (e >= n || !requests[e]) return;
  uint k = atomic_inc(count);
  if (k < capacity) list[k] = (uint2)(e, caps[e]);
}

/* Writes the frame's page-table entries (index, value) into a table filled
 * with zeros: a few thousand entries rather than the whole table. */
__kernel void set_page_entries(__global const uint2* writes, uint count, __global uint* table) {
  uint i = get_global_id(0);
  if (i < count) table[writes[i].x] = writes[i].y;
}

/* Sets every texel of the listed physical pages to "nothing here", and
 * marks them for occlusion culling's next look (shadow_page_farthest). */
__kernel void clear_shadow_pages(__global const uint* pages, uint texel_count, __global uint* pool,
                                 __global uchar* dirty) {
  uint i = get_global_id(0);
  if (i >= texel_count) return;
  uint page = pages[i / MP_PAGE_TEXELS];
  pool[(ulong)page * MP_PAGE_TEXELS + (ulong)(i % MP_PAGE_TEXELS)] = MP_SHADOW_EMPTY;
  if (i % MP_PAGE_TEXELS == 0u) dirty[page] = 1;
}

/* The farthest depth of each 16 x 16-texel cell of the listed pages that
 * the shadow pass wrote to since the last look (dirty), and of each page,
 * into the occlusion pyramid's buffer (mp_page_occluded): one work-group of
 * 64 per page, a work-item per cell. No deeper than the page's cap (caps,
 * as the list: the farthest receiver that asked for it, requests): what
 * lies beyond shadows none of them. */
__kernel __attribute__((reqd_work_group_size(64, 1, 1))) void shadow_page_farthest(
    __global const uint* pages, __global const uint* caps, uint count, __global const uint* pool,
    __global uchar* dirty, __global uint* pyramid, uint page_cells, uint page_farthest) {
  __local uint part[64];
  uint g = get_group_id(0), l = get_local_id(0);
  if (g >= count) return;
  uint page = pages[g];
  if (!dirty[page]) return; /* the same for the whole group */
  uint m = 0u;
  __global const uint* texels = pool + (ulong)page * MP_PAGE_TEXELS + (ulong)((l >> 3) * 16u * MP_PAGE_SIZE + (l & 7u) * 16u);
  for (uint y = 0; y < 16u; ++y)
    for (uint x = 0; x < 16u; ++x) m = max(m, texels[y * MP_PAGE_SIZE + x]);
  m = min(m, caps[g]);
  pyramid[page_cells + page * 64u + l] = m;
  part[l] = m;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint s = 32u; s > 0u; s >>= 1) {
    if (l < s) part[l] = max(part[l], part[l + s]);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0u) pyramid[page_farthest + page] = part[0], dirty[page] = 0;
}

/* Each view's occlusion pyramid (mp_page_occluded), one work-group per view:
 * level 0 names the pages rendered in this pass (physical page + 1, 0
 * elsewhere), level 1 holds the farthest depth of the 2 x 2 pages below,
 * each next level the largest of four below. */
__kernel void shadow_occlusion_build(__global const FrameParams* views, __global const uint* page_table,
                                     __global uint* pyramid, uint page_farthest) {
  FrameParams v = views[get_group_id(0)];
  uint l = get_local_id(0), step = get_local_size(0);
  int n = v.page_side;
  uint offset = v.page_mask;
  for (uint i = l; i < (uint)(n * n); i += step) {
    int sx = ((int)(i % (uint)n) + v.page_origin_x) & (n - 1), sy = ((int)(i / (uint)n) + v.page_origin_y) & (n - 1);
    uint e = page_table[v.page_table + (uint)(sy * n + sx)];
    pyramid[offset + i] = (e & MP_PAGE_RENDER) ? MP_PAGE_PHYSICAL(e) + 1u : 0u;
  }
  barrier(CLK_GLOBAL_MEM_FENCE);
  for (int level = 1; n > 1; n >>= 1, ++level) {
    int h = n / 2;
    uint up = offset + (uint)(n * n);
    for (uint i = l; i < (uint)(h * h); i += step) {
      int x = (int)(i % (uint)h), y = (int)(i / (uint)h);
      uint below[4] = {pyramid[offset + (uint)(2 * y * n + 2 * x)], pyramid[offset + (uint)(2 * y * n + 2 * x + 1)],
                       pyramid[offset + (uint)((2 * y + 1) * n + 2 * x)],
                       pyramid[offset + (uint)((2 * y + 1) * n + 2 * x + 1)]};
      uint m = 0u;
      for (int c = 0; c < 4; ++c) {
        uint d = below[c];
        if (level == 1 && d != 0u) d = pyramid[page_farthest + d - 1u];
        m = max(m, d);
      }
      pyramid[up + i] = m;
    }
    barrier(CLK_GLOBAL_MEM_FENCE);
    offset = up;
  }
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
void shadow_sample(MP_SCENE_PARAMS __global const SubPatch* diceable, uint first, uint count,
                   __global const uint* offsets, uint base, uint total, FrameParams f,
                   __global const FrameParams* views, __global const float4* grid_p, __global const float4* grid_c,
                   __global const uint* page_table, volatile __global uint* pool, __global uchar* dirty) {
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
  float o[4];
  for (int k = 0; k < 4; ++k) o[k] = mat->program[3] > 0.0f ? grid_c[grid_base + q[k]].w : mat->opacity[3];
  float opacity = mp_quad_opacity(o[0], o[1], o[2], o[3]);
  /* Per texel, the opacity interpolated in the triangle that covers it and
   * a threshold drawn for the patch and texel, or one half where a hard
   * alpha cut crosses the micropolygon (as mp_opacity_keeps keeps the
   * camera's samples): a hard alpha cut casts a crisp-edged shadow. */
  float to[2][3] = {{o[0], tris[0].swapped ? o[2] : o[1], tris[0].swapped ? o[1] : o[2]},
                    {o[0], tris[1].swapped ? o[3] : o[2], tris[1].swapped ? o[2] : o[3]}};
  uint surface = opacity < 1.0f ? mp_opacity_surface(mp_placed_patch_id(sp.patch, sp.instance)) : 0u;
  int cut = mat->program[3] > 1.5f || mp_quad_cut(o[0], o[1], o[2], o[3]);
  int side = v.page_side;
  /* Most micropolygons lie within one page: one table lookup for all. */
  int one_page = (px0 >> 7) == (px1 >> 7) && (py0 >> 7) == (py1 >> 7);
  uint e = 0u;
  if (one_page) {
    int sx = ((px0 >> 7) + v.page_origin_x) & (side - 1), sy = ((py0 >> 7) + v.page_origin_y) & (side - 1);
    e = page_table[v.page_table + (uint)(sy * side + sx)];
    if (!(e & MP_PAGE_RENDER)) return;
    dirty[MP_PAGE_PHYSICAL(e)] = 1;
  }
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      if (!one_page) {
        int sx = ((px >> 7) + v.page_origin_x) & (side - 1), sy = ((py >> 7) + v.page_origin_y) & (side - 1);
        uint was = e;
        e = page_table[v.page_table + (uint)(sy * side + sx)];
        if (!(e & MP_PAGE_RENDER)) continue;
        if (e != was) dirty[MP_PAGE_PHYSICAL(e)] = 1;
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
      if (opacity < 1.0f && (cut ? 0.5f : mp_hash_unit(mp_hash_combine(surface, (uint)(py * v.width + px)))) >=
                                la * to[t][0] + lb * to[t][1] + lc * to[t][2])
        continue;
      atomic_min(&pool[(ulong)MP_PAGE_PHYSICAL(e) * MP_PAGE_TEXELS + texel], as_uint(d));
    }
}
