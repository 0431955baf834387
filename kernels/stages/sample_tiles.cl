/* Sample, shaped for CPUs: a sort-middle rasteriser (Laine & Karras 2011,
 * "High-performance software rasterization on GPUs"; RenderMan's buckets).
 * Each grid's vertices are projected once (project_grids; before shading
 * when visibility first takes the batch, its passes sharing the lists)
 * and each run of its micropolygons is bounded in screen tiles of
 * MP_RASTER_TILE pixels (bound_runs); the host sorts the runs into per-tile
 * lists; then one work-item per tile rasterises its runs' micropolygons into the
 * tile's samples, which no other work-item touches. So there are no atomics
 * and one pass writes depth and attributes together: a sample's nearest key
 * so far is in hand when a micropolygon covers it. The nearest key wins
 * whatever the order, so the image equals the per-micropolygon sampler's
 * (sample.cl), with the same fixed-point edge tests (mp_raster.h, kept
 * watertight) and the same arithmetic for depth and attributes
 * (mp_sample.h). On a GPU one work-item per tile leaves most lanes idle,
 * so GPUs keep sample.cl. */
/* Left out where the device's compiler cannot build it
 * (DeviceSession::tile_sampler). */
#ifndef MP_NO_TILE_SAMPLER
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "core/mp_hash.h"
#include "stages/mp_raster.h"
#include "geometry/mp_grid.h"
#include "stages/mp_sample.h"
#include "core/mp_scene_data.h"

/* A projected vertex: fixed-point raster x and y, 1/depth's bits, and 1
 * where the vertex cannot be rasterised (behind the eye, past the guard
 * band): its micropolygons are skipped, as sample.cl skips them. */
#define MP_PROJECTED_INVALID 1

/* One work-item per grid of diceable sub-patches [first, first + count):
 * its vertices' raster positions, into `projected` slot for slot as the
 * grid buffers. */
__kernel void project_grids(__global const SubPatch* diceable, uint first, uint count, FrameParams f,
                            __global const float4* grid_p, __global int4* projected) {
  uint k = get_global_id(0);
  if (k >= count) return;
  uint slot = first + k, stride = (uint)f.max_grid + 1u;
  SubPatch sp = diceable[slot];
  MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
  uint n = mp_grid_vertices(&g);
  ulong base = (ulong)slot * stride * stride;
  for (uint o = 0u; o < n; ++o) {
    uint i, j;
    mp_grid_vertex_slot(&g, o, &i, &j);
    ulong idx = base + mp_slot(&g, i, j);
    int ok = 1;
    float inv_d;
    MpFixed2 q = mp_raster_position(grid_p[idx], f, &inv_d, &ok);
    projected[idx] = ok ? (int4)((int)q.x, (int)q.y, as_int(inv_d), 0) : (int4)(0, 0, 0, MP_PROJECTED_INVALID);
  }
}

/* Micropolygon m of the grid whose slots start at `base`: its corners'
 * slots (q) and projected vertices (r); 0 where one of them cannot be
 * rasterised (the micropolygon is skipped, as sample.cl skips it). */
inline int mp_projected_micropolygon(__global const int4* projected, ulong base, const MpGridShape* g, uint m, uint* q,
                                     int4* r) {
  mp_grid_micropolygon(g, m, q);
  for (int k = 0; k < 4; ++k) r[k] = projected[base + q[k]];
  return (r[0].w | r[1].w | r[2].w | r[3].w) == 0;
}

/* One work-item per run r of grid k (runs_per_grid per grid): the screen
 * tiles the run's micropolygons reach, (tx0, ty0, tx1, ty1), tx0 > tx1
 * where none (clipped to the frame). */
__kernel void bound_runs(__global const SubPatch* diceable, uint first, uint count, FrameParams f,
                         __global const int4* projected, uint runs_per_grid, __global int4* rects) {
  uint gid = get_global_id(0), m0, m1;
  MpGridShape g;
  ulong base;
  if (!mp_grid_run(diceable, first, count, gid, runs_per_grid, f, &g, &base, &m0, &m1)) return;
  int x0 = INT_MAX, y0 = INT_MAX, x1 = INT_MIN, y1 = INT_MIN;
  for (uint m = m0; m < m1; ++m) {
    uint q[4];
    int4 r[4];
    if (!mp_projected_micropolygon(projected, base, &g, m, q, r)) continue;
    for (int k = 0; k < 4; ++k) x0 = min(x0, r[k].x), x1 = max(x1, r[k].x), y0 = min(y0, r[k].y), y1 = max(y1, r[k].y);
  }
  int4 r = (int4)(1, 1, 0, 0);
  if (x0 <= x1 && x1 >= 0 && y1 >= 0 && (x0 >> MP_SUBPIXEL_BITS) < f.width && (y0 >> MP_SUBPIXEL_BITS) < f.height) {
    int px0 = max(x0 >> MP_SUBPIXEL_BITS, 0), px1 = min(x1 >> MP_SUBPIXEL_BITS, f.width - 1);
    int py0 = max(y0 >> MP_SUBPIXEL_BITS, 0), py1 = min(y1 >> MP_SUBPIXEL_BITS, f.height - 1);
    r = (int4)(px0 / MP_RASTER_TILE, py0 / MP_RASTER_TILE, px1 / MP_RASTER_TILE, py1 / MP_RASTER_TILE);
  }
  rects[gid] = r;
}

inline MpFixed2 mp_projected_position(int4 v) {
  MpFixed2 p;
  p.x = (long)v.x;
  p.y = (long)v.y;
  return p;
}

/* What a tile pass does with a covered sample whose key is `key`, the
 * sample's nearest so far `old` (kind: MP_SAMPLE_KIND of the pass; owned:
 * the batch's opaque grids already hold their keys, MP_SAMPLE_AFTER_MARK):
 * 1 to take it (the depth, and the attributes unless only depth is
 * sought), 0 to leave it, and in the mark pass *marked where it owns it. */
inline int mp_tile_takes(ulong key, ulong old, uint kind, int owned, int* marked) {
  if (kind == MP_SAMPLE_MARK) {
    if (key == old) *marked = 1;
    return 0;
  }
  return owned ? key <= old : key < old;
}

/* The same samples one at a time in 64-bit arithmetic (mp_edge_triangle_covers),
 * for micropolygons too large for the int32 path, not opaque or held out
 * (cover: MpCover). kind, owned, marked: mp_tile_takes. */
inline uint mp_sample_tile_slow(const MpTriangle* tris, long xmin, long xmax, long ymin, long ymax, int px0, int px1,
                                int py0, int py1, uint mp_id, MpCover cover, FrameParams f,
                                __global const ushort* sample_offsets, __global ulong* keys, __global float* colors,
                                __global uint* normals, uint kind, int owned, int* written, int* marked) {
  int spp = f.spp_x * f.spp_y;
  uint tests = 0u;
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      ulong pixel = (ulong)py * (ulong)f.width + (ulong)px;
      for (int s = 0; s < spp; ++s) {
        MpFixed2 sq = mp_sample_position(px, py, s, spp, f, sample_offsets);
        if (sq.x < xmin || sq.x > xmax || sq.y < ymin || sq.y > ymax) continue;
        ++tests;
        float la, lb, lc, d;
        int t = mp_quad_covers(tris, sq, &la, &lb, &lc);
        if (t < 0 || !mp_triangle_depth(&tris[t], la, lb, lc, f, &d)) continue;
        if (!mp_opacity_keeps(cover.surface, cover.cut, px, py, s, mp_sample_opacity(&tris[t], la, lb, lc, d, cover.opacity, f),
                              f))
          continue;
        ulong key = mp_sample_key(d, mp_id), index = pixel * (ulong)spp + (ulong)s;
        if (!mp_tile_takes(key, keys[index], kind, owned, marked)) {
          if (*marked) return tests;
          continue;
        }
        keys[index] = key;
        *written = 1;
        if (kind == MP_SAMPLE_OPAQUE_DEPTH) continue;
        float3 col, nrm;
        mp_triangle_attributes(&tris[t], la, lb, lc, d, f, &col, &nrm);
        mp_store_color(colors, pixel, s, spp, mp_sample_color(col, cover.holdout), f);
        if (f.normal_pass) normals[index] = mp_encode_normal(normalize(nrm));
      }
    }
  return tests;
}

/* Samples are tested 16 at a time (one pixel's, a chunk of
 * MP_LANES), in int32: a micropolygon whose raster bound spans at most
 * MP_FAST_SPAN fixed-point units per axis keeps every edge value of every
 * sample within a pixel of its bound below 2^28, so the int32 sums equal
 * mp_edge's 64-bit ones exactly and coverage stays watertight. */
#define MP_LANES 16

/* An edge u -> v of a triangle as the 16-lane tests use it: its value at
 * the corner of the first pixel of the micropolygon's range, and its steps
 * per fixed-point unit in x and y (e(p + o) = e(p) + dx o.x + dy o.y, with
 * mp_edge_triangle_covers' sign: inside is >= 0), and its tie rule. */
typedef struct {
  int e, dx, dy, owns;
} MpEdge16;

inline MpEdge16 mp_edge16(MpFixed2 u, MpFixed2 v, MpFixed2 p, int owns) {
  MpEdge16 r;
  r.e = -(int)mp_edge(u, v, p);
  r.dx = (int)(v.y - u.y);
  r.dy = -(int)(v.x - u.x);
  r.owns = owns ? -1 : 0;
  return r;
}

/* Lanes (-1) where the sample at offset (ox, oy) from a pixel whose corner
 * is (sx, sy) units from the range's first corner lies inside the edge
 * (mp_edge_inside); its value in *value. */
inline int16 mp_inside16(const MpEdge16* g, int sx, int sy, int16 ox, int16 oy, int16* value) {
  int base = g->e + g->dx * sx + g->dy * sy;
  int16 e = (int16)base + (int16)g->dx * ox + (int16)g->dy * oy;
  *value = e;
  return (e > 0) | ((e == 0) & (int16)g->owns);
}

/* A micropolygon's samples in pixels [px0, px1] x [py0, py1] of a tile,
 * 16 at a time: coverage, depth, the key comparison and the attributes in
 * vectors; keys and colors of a whole chunk of a pixel's samples are
 * stored as vectors, a partial chunk's (the lanes past the pixel's samples
 * belong to other pixels) and normals one by one. Opaque micropolygons
 * only, none held out (the stochastic opacity and holdout are per sample:
 * mp_sample_tile_slow). kind, owned, marked: mp_tile_takes. */
inline uint mp_sample_tile_fast(const MpTriangle* tris, long xmin, long xmax, long ymin, long ymax, int px0, int px1,
                                int py0, int py1, uint mp_id, FrameParams f, __global const ushort* soa,
                                __global ulong* keys, __global float* colors, __global uint* normals, uint kind,
                                int owned, int* written, int* marked) {
  int spp = f.spp_x * f.spp_y, chunks = (spp + MP_LANES - 1) / MP_LANES;
  const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  uint tests = 0u;
  MpFixed2 p0;
  p0.x = (long)px0 << MP_SUBPIXEL_BITS;
  p0.y = (long)py0 << MP_SUBPIXEL_BITS;
  MpEdge16 g[6];
  for (int t = 0; t < 2; ++t) {
    g[3 * t + 0] = mp_edge16(tris[t].e.b, tris[t].e.c, p0, tris[t].e.own0);
    g[3 * t + 1] = mp_edge16(tris[t].e.c, tris[t].e.a, p0, tris[t].e.own1);
    g[3 * t + 2] = mp_edge16(tris[t].e.a, tris[t].e.b, p0, tris[t].e.own2);
  }
  int16 valid0 = (int16)(tris[0].e.valid ? -1 : 0), valid1 = (int16)(tris[1].e.valid ? -1 : 0);
  float dl[MP_LANES], cx[MP_LANES], cy[MP_LANES], cz[MP_LANES], nx[MP_LANES], ny[MP_LANES], nz[MP_LANES];
  int cov[MP_LANES];
  for (int py = py0; py <= py1; ++py)
    for (int px = px0; px <= px1; ++px) {
      int sx = (px - px0) << MP_SUBPIXEL_BITS, sy = (py - py0) << MP_SUBPIXEL_BITS;
      int tp = ((py + f.crop_y0) & (MP_SAMPLE_TILE - 1)) * MP_SAMPLE_TILE + ((px + f.crop_x0) & (MP_SAMPLE_TILE - 1));
      ulong pixel = (ulong)py * (ulong)f.width + (ulong)px;
      /* The bound relative to this pixel's corner, for the samples it holds. */
      int bx0 = (int)(xmin - ((long)px << MP_SUBPIXEL_BITS)), bx1 = (int)(xmax - ((long)px << MP_SUBPIXEL_BITS));
      int by0 = (int)(ymin - ((long)py << MP_SUBPIXEL_BITS)), by1 = (int)(ymax - ((long)py << MP_SUBPIXEL_BITS));
      for (int c = 0; c < chunks; ++c) {
        __global const ushort* o = soa + ((ulong)tp * (ulong)chunks + (ulong)c) * (2 * MP_LANES);
        int16 ox = convert_int16(vload16(0, o)), oy = convert_int16(vload16(1, o));
        int16 live = lane < (int16)(spp - c * MP_LANES);
        /* Samples inside the bound: the ones sample.cl tests (a statistic). */
        int16 inbox = live & (ox >= (int16)bx0) & (ox <= (int16)bx1) & (oy >= (int16)by0) & (oy <= (int16)by1);
        int8 h8 = inbox.lo + inbox.hi;
        int4 h4 = h8.lo + h8.hi;
        int2 h2 = h4.lo + h4.hi;
        tests += (uint)(-(h2.x + h2.y));
        int16 a0, a1, a2, b0, b1, b2;
        int16 in0 = valid0 & inbox & mp_inside16(&g[0], sx, sy, ox, oy, &a0) & mp_inside16(&g[1], sx, sy, ox, oy, &a1) &
                    mp_inside16(&g[2], sx, sy, ox, oy, &a2);
        int16 in1 = valid1 & inbox & ~in0 & mp_inside16(&g[3], sx, sy, ox, oy, &b0) &
                    mp_inside16(&g[4], sx, sy, ox, oy, &b1) & mp_inside16(&g[5], sx, sy, ox, oy, &b2);
        int16 covered = in0 | in1;
        if (!any(covered)) continue;
        /* Barycentrics of the covering triangle, in its own vertex order. */
        float16 la = select(convert_float16(b0) * tris[1].e.inv_area, convert_float16(a0) * tris[0].e.inv_area, in0);
        float16 lb = select(convert_float16(b1) * tris[1].e.inv_area, convert_float16(a1) * tris[0].e.inv_area, in0);
        float16 lc = select(convert_float16(b2) * tris[1].e.inv_area, convert_float16(a2) * tris[0].e.inv_area, in0);
        float16 da = select((float16)tris[1].a.inv_d, (float16)tris[0].a.inv_d, in0);
        float16 db = select((float16)tris[1].b.inv_d, (float16)tris[0].b.inv_d, in0);
        float16 dc = select((float16)tris[1].c.inv_d, (float16)tris[0].c.inv_d, in0);
        float16 inv_d = la * da + lb * db + lc * dc;
        float16 d = f.ortho ? inv_d : (float16)1.0f / inv_d;
        covered &= (d >= (float16)f.clip_near) & (d <= (float16)f.clip_far);
        if (!any(covered)) continue;
        int first = c * MP_LANES, lanes = min(MP_LANES, spp - first);
        int whole = lanes == MP_LANES;
        ulong16 old;
        __global ulong* kp = keys + pixel * (ulong)spp + (ulong)first;
        if (whole) {
          /* A whole chunk of this pixel's samples: keys compared 16 at once. */
          old = vload16(0, kp);
          ulong16 key = (convert_ulong16(as_uint16(d)) << (ulong16)32) | (ulong16)(ulong)mp_id;
          if (kind == MP_SAMPLE_MARK) {
            if (any(convert_long16(covered) & (key == old))) {
              *marked = 1;
              return tests;
            }
            continue;
          }
          long16 wins = convert_long16(covered) & (owned ? key <= old : key < old);
          if (!any(wins)) continue;
          vstore16(select(old, key, wins), 0, kp);
          covered = convert_int16(wins);
          *written = 1;
          if (kind == MP_SAMPLE_OPAQUE_DEPTH) continue;
        }
        float16 w = f.ortho ? (float16)1.0f : d;
#define MP_ATTRIBUTE16(field, comp)                                                                        \
  ((la * select((float16)tris[1].a.field.comp, (float16)tris[0].a.field.comp, in0) +                     \
    lb * select((float16)tris[1].b.field.comp, (float16)tris[0].b.field.comp, in0) +                     \
    lc * select((float16)tris[1].c.field.comp, (float16)tris[0].c.field.comp, in0)) * w)
        float16 r = MP_ATTRIBUTE16(c_over_d, x), gr = MP_ATTRIBUTE16(c_over_d, y), bl = MP_ATTRIBUTE16(c_over_d, z);
        /* No holdout here: a held-out share of 0 in blue's low bits (mp_sample.h). */
        bl = as_float16(as_uint16(bl) & (uint16)(~0xffu));
        if (whole) {
          __global float* cp = colors + mp_color_index(pixel, spp, 0) + (ulong)first;
          vstore16(select(vload16(0, cp), r, covered), 0, cp);
          vstore16(select(vload16(0, cp + spp), gr, covered), 0, cp + spp);
          vstore16(select(vload16(0, cp + 2 * spp), bl, covered), 0, cp + 2 * spp);
          if (!f.normal_pass) continue;
        }
        vstore16(r, 0, cx);
        vstore16(gr, 0, cy);
        vstore16(bl, 0, cz);
        if (f.normal_pass) {
          vstore16(MP_ATTRIBUTE16(n_over_d, x), 0, nx);
          vstore16(MP_ATTRIBUTE16(n_over_d, y), 0, ny);
          vstore16(MP_ATTRIBUTE16(n_over_d, z), 0, nz);
        }
#undef MP_ATTRIBUTE16
        vstore16(d, 0, dl);
        vstore16(covered, 0, cov);
        for (int l = 0; l < lanes; ++l) {
          if (!cov[l]) continue;
          ulong index = pixel * (ulong)spp + (ulong)(first + l);
          if (!whole) {
            ulong key = mp_sample_key(dl[l], mp_id);
            if (!mp_tile_takes(key, keys[index], kind, owned, marked)) {
              if (*marked) return tests;
              continue;
            }
            keys[index] = key;
            *written = 1;
            if (kind == MP_SAMPLE_OPAQUE_DEPTH) continue;
            mp_store_color(colors, pixel, first + l, spp, (float3)(cx[l], cy[l], cz[l]), f);
          }
          if (f.normal_pass) normals[index] = mp_encode_normal(normalize((float3)(nx[l], ny[l], nz[l])));
        }
      }
    }
  return tests;
}

/* One work-item per active tile (tile_ids[a], whose runs are
 * entries[starts[a], starts[a + 1]), ascending; entry slot *
 * runs_per_grid + run): every micropolygon of
 * those grids whose raster bound meets the tile is tested against the
 * tile's samples under that bound. totals: micropolygons, twice their area
 * (fixed-point units) and samples tested, each micropolygon counted in the
 * tile that holds its bound's first pixel, in the pass that finds its depth;
 * totals[4]: those of them that a plain pass (MP_SAMPLE_ATTRIBUTES alone)
 * found hidden, writing no sample of that tile.
 * pass: MP_SAMPLE_ATTRIBUTES (depth and attributes), or visibility first's
 * MP_SAMPLE_OPAQUE_DEPTH and MP_SAMPLE_MARK (marks in `visible`, a byte per
 * grid slot), and MP_SAMPLE_AFTER_MARK on the pass after shading. */
__kernel void sample_tiles(MP_SCENE_PARAMS __global const SubPatch* diceable, FrameParams f,
                           __global const int4* projected, __global const float4* grid_c,
                           __global const float4* grid_n, __global const ushort* sample_offsets,
                           __global const ushort* sample_soa, __global const uint* tile_ids, __global const uint* starts,
                           __global const uint* entries, uint runs_per_grid, uint first_tile, uint active,
                           uint tiles_x, __global ulong* keys, __global float* colors, __global uint* normals,
                           volatile __global ulong* totals, __global uchar* occlusion_dirty, OcclusionParams occ,
                           uint pass, __global uchar* visible) {
  uint a = first_tile + get_global_id(0);
  if (a >= active) return;
  uint tile = tile_ids[a];
  int tx0 = (int)(tile % tiles_x) * MP_RASTER_TILE, ty0 = (int)(tile / tiles_x) * MP_RASTER_TILE;
  int tx1 = min(tx0 + MP_RASTER_TILE, f.width) - 1, ty1 = min(ty0 + MP_RASTER_TILE, f.height) - 1;
  /* The tile's samples lie in this fixed-point rectangle. */
  long fx0 = (long)tx0 << MP_SUBPIXEL_BITS, fx1 = ((long)(tx1 + 1) << MP_SUBPIXEL_BITS) - 1;
  long fy0 = (long)ty0 << MP_SUBPIXEL_BITS, fy1 = ((long)(ty1 + 1) << MP_SUBPIXEL_BITS) - 1;
  uint stride = (uint)f.max_grid + 1u;
  ulong counted = 0u, area_sum = 0u, tests = 0u, lost = 0u;
  int wx0 = tx1 + 1, wx1 = tx0 - 1, wy0 = ty1 + 1, wy1 = ty0 - 1; /* pixels written */
  uint kind = pass & MP_SAMPLE_KIND;
  int after = (pass & MP_SAMPLE_AFTER_MARK) != 0u;
  for (uint e = starts[a]; e < starts[a + 1u]; ++e) {
    uint slot = entries[e] / runs_per_grid, run = entries[e] % runs_per_grid;
    SubPatch sp = diceable[slot];
    /* Which grids this pass takes (as sample.cl's mp_sample). */
    int opaque = mp_material_opaque(materials, patch_info, sp.patch);
    if (kind == MP_SAMPLE_OPAQUE_DEPTH ? !opaque
        : kind == MP_SAMPLE_MARK       ? !opaque || visible[slot]
                                       : after && opaque && !visible[slot])
      continue;
    int owned = after && opaque;
    int finds_depth = kind == MP_SAMPLE_OPAQUE_DEPTH || (kind == MP_SAMPLE_ATTRIBUTES && !owned);
    int marked = 0;
    MpGridShape g = mp_grid_shape(&sp, (uint)f.max_grid);
    uint flags = mp_placed_flags(patch_info, instances, sp.patch, sp.instance);
    uint grid_id = mp_grid_id(&sp);
    ulong base = (ulong)slot * stride * stride;
    uint nm = min(mp_grid_micropolygons(&g), (run + 1u) * MP_TILE_RUN);
    for (uint m = run * MP_TILE_RUN; m < nm; ++m) {
      uint q[4];
      int4 r[4];
      if (!mp_projected_micropolygon(projected, base, &g, m, q, r)) continue;
      MpFixed2 p[4];
      for (int k = 0; k < 4; ++k) p[k] = mp_projected_position(r[k]);
      long xmin = min(min(p[0].x, p[1].x), min(p[2].x, p[3].x)), xmax = max(max(p[0].x, p[1].x), max(p[2].x, p[3].x));
      long ymin = min(min(p[0].y, p[1].y), min(p[2].y, p[3].y)), ymax = max(max(p[0].y, p[1].y), max(p[2].y, p[3].y));
      if (xmax < fx0 || xmin > fx1 || ymax < fy0 || ymin > fy1) continue;
      long area2;
      uint keep = mp_quad_facing(p[0], p[1], p[2], p[3], flags, f, &area2);
      if (!keep) continue;
      /* Counted once: in the tile of the bound's first pixel in the frame. */
      long hx = clamp(xmin >> MP_SUBPIXEL_BITS, (long)0, (long)f.width - 1);
      long hy = clamp(ymin >> MP_SUBPIXEL_BITS, (long)0, (long)f.height - 1);
      int here = finds_depth && hx >= tx0 && hx <= tx1 && hy >= ty0 && hy <= ty1;
      if (here) {
        counted += area2 > 0 ? 1u : 0u;
        area_sum += (ulong)area2;
      }
      MpRasterVertex v[4];
      for (int k = 0; k < 4; ++k)
        v[k] = mp_raster_attributes(p[k], as_float(r[k].z), grid_c[base + q[k]], grid_n[base + q[k]], f);
      MpTriangle tris[2];
      mp_setup_quad(v, keep, tris);
      uint mp_id = mp_micropolygon_id(grid_id, m);
      MpCover cover = {mp_quad_opacity(grid_c[base + q[0]].w, grid_c[base + q[1]].w, grid_c[base + q[2]].w,
                                       grid_c[base + q[3]].w),
                       mp_quad_opacity(grid_n[base + q[0]].w, grid_n[base + q[1]].w, grid_n[base + q[2]].w,
                                       grid_n[base + q[3]].w),
                       mp_opacity_surface(mp_placed_patch_id(sp.patch, sp.instance)),
                       mp_material_cut(materials, patch_info, sp.patch) ||
                           mp_quad_cut(grid_c[base + q[0]].w, grid_c[base + q[1]].w, grid_c[base + q[2]].w,
                                       grid_c[base + q[3]].w)};
      /* Before shading, the grid's colours are not yet its own: opaque. */
      if (kind != MP_SAMPLE_ATTRIBUTES) cover.opacity = 1.0f, cover.holdout = 0.0f, cover.cut = 0;
      int px0 = (int)max(xmin >> MP_SUBPIXEL_BITS, (long)tx0), px1 = (int)min(xmax >> MP_SUBPIXEL_BITS, (long)tx1);
      int py0 = (int)max(ymin >> MP_SUBPIXEL_BITS, (long)ty0), py1 = (int)min(ymax >> MP_SUBPIXEL_BITS, (long)ty1);
      int written = 0;
      uint t;
      if (xmax - xmin <= MP_FAST_SPAN && ymax - ymin <= MP_FAST_SPAN && cover.opacity >= 1.0f && !(cover.holdout > 0.0f))
        t = mp_sample_tile_fast(tris, xmin, xmax, ymin, ymax, px0, px1, py0, py1, mp_id, f, sample_soa, keys, colors,
                                normals, kind, owned, &written, &marked);
      else
        t = mp_sample_tile_slow(tris, xmin, xmax, ymin, ymax, px0, px1, py0, py1, mp_id, cover, f, sample_offsets,
                                keys, colors, normals, kind, owned, &written, &marked);
      if (finds_depth) tests += t;
      /* Hidden when sampled: what visibility first would have left unshaded
       * (a lower bound, per micropolygon; VisibilityChoice reads it). */
      lost += here && !written && pass == MP_SAMPLE_ATTRIBUTES;
      if (written) wx0 = min(wx0, px0), wx1 = max(wx1, px1), wy0 = min(wy0, py0), wy1 = max(wy1, py1);
      if (marked) {
        visible[slot] = (uchar)1;
        break;
      }
    }
  }
  if (occlusion_dirty && wx0 <= wx1) mp_mark_occlusion_rect(occlusion_dirty, occ, f, wx0, wy0, wx1, wy1);
  if (counted || tests) {
    atom_add(&totals[0], counted);
    atom_add(&totals[1], area_sum);
    atom_add(&totals[2], tests);
    atom_add(&totals[4], lost);
  }
}

#endif /* MP_NO_TILE_SAMPLER */
