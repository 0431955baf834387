/* Micropolygon rasterisation math shared by the sampler, the resolve pass and
 * host tests: fixed-point sub-pixel positions, jittered stratified samples and
 * edge functions with a consistent tie rule (Fatahalian et al. 2009; Pineda
 * 1988). Raster space: x right, y down, pixel (px, py) covers
 * [px, px+1) x [py, py+1). */
#ifndef MP_RASTER_H
#define MP_RASTER_H

#include "core/mp_compat.h"
#include "core/mp_hash.h"
#include "stages/mp_blur.h"
#include "core/mp_types.h"

#define MP_SUBPIXEL_BITS 8
#define MP_SUBPIXEL_ONE 256
/* Vertices further than this many pixels outside the frame are not rasterised
 * (they belong to micropolygons the frustum test let through only partly). */
#define MP_RASTER_GUARD 1.0e6f

typedef struct {
  long x, y;
} MpFixed2;

/* A micropolygon's opacity: the mean of its corners' (a cut-out's edge
 * then falls where its alpha crosses, not on one corner's side). Its
 * held-out share (Holdout, grid normals' w after shading) is the same mean. */
MP_INLINE float mp_quad_opacity(float a, float b, float c, float d) { return 0.25f * (a + b + c + d); }

/* Whether a micropolygon's corners are each fully opaque or fully clear,
 * some clear: a hard alpha cut (Math Greater Than and the like) crosses it.
 * Its samples and texels then keep it where the opacity interpolated across
 * it exceeds one half, so the cut's edge is crisp on the line halfway
 * between its opaque and clear corners, as a binary alpha's edge is in
 * Cycles; thresholds drawn per sample would dither it across the whole
 * micropolygon, noise along every cut edge at 16 samples per pixel. */
MP_INLINE int mp_quad_cut(float a, float b, float c, float d) {
  int binary = (a == 0.0f || a == 1.0f) && (b == 0.0f || b == 1.0f) && (c == 0.0f || c == 1.0f) &&
               (d == 0.0f || d == 1.0f);
  return binary && a + b + c + d < 4.0f;
}

/* Whether a patch's material writes its alpha as a hard cut's edge distance
 * (mp_alpha_cut; DeviceMaterial.program[3] = 2): kept above one half too,
 * so the edge falls where the cut does within the micropolygon. */
MP_INLINE int mp_material_cut(const MP_GLOBAL DeviceMaterial* materials, const MP_GLOBAL uint* patch_info,
                              uint patch) {
  return materials[patch_info[4 * (ulong)patch + 1]].program[3] > 1.5f;
}

/* The surface whose micropolygons share stochastic-opacity thresholds (the
 * camera's, mp_sample.h, and the shadow maps'): a patch, so neighbouring
 * grids of one patch agree. */
MP_INLINE uint mp_opacity_surface(uint patch) { return mp_hash32(patch ^ 0x6f706163u); }

MP_INLINE long mp_to_fixed(float r) { return (long)floor(r * (float)MP_SUBPIXEL_ONE + 0.5f); }

/* Sample positions repeat over tiles of MP_SAMPLE_TILE x MP_SAMPLE_TILE
 * pixels: one jittered sample per stratum of a spp_x x spp_y grid, offsets in
 * 1/256 pixel packed as x | y << 8. The table is built on the host from this
 * function and read by the sampler and the resolve pass, which must agree. */
#define MP_SAMPLE_TILE 32

/* Pixels per side of the screen tiles the CPU's sampler bins grids into
 * (sample_tiles.cl): a tile's samples belong to one work-item. */
#define MP_RASTER_TILE 32
/* It bins each grid's micropolygons by runs of this many (in the grid's
 * order: rows of the interior, then the strips), whose bounds are tight
 * where a whole grid's would put each micropolygon in front of every tile
 * the grid touches. */
#define MP_TILE_RUN 16

/* The binned sampler (sample_bins.cl): a work-group of
 * MP_BIN_GROUP work-items per bin of screen pixels, whose samples' keys it
 * holds in local memory (the bin's side is chosen per frame by the samples
 * per pixel: SampleStage::bin_side). A run of micropolygons reaching more
 * than MP_BIN_RUN_TILES bins is left to the per-micropolygon sampler, so
 * the lists never hold more than that many entries per run. */
#define MP_BIN_GROUP 256
#define MP_BIN_RUN_TILES 8

/* A micropolygon whose raster bound spans at most this many fixed-point
 * units per axis is tested in int32 arithmetic by both samplers (sample.cl,
 * sample_tiles.cl): its edge values at the samples they test stay far
 * below 2^31, so they equal mp_edge's 64-bit ones exactly. */
#define MP_FAST_SPAN (32 << MP_SUBPIXEL_BITS)

/* The samplers' passes over a batch's grids (sample.cl; the tile sampler
 * does depth and attributes in one pass, MP_SAMPLE_ATTRIBUTES). Visibility
 * first (docs/pipeline.md, step 5): before shading, the nearest keys of the
 * grids whose material is opaque whatever its shading (mp_material_opaque),
 * then a mark on each such grid that owns a sample; shading skips the
 * unmarked ones, and the passes after it, flagged MP_SAMPLE_AFTER_MARK,
 * leave the opaque grids' depth as it is and skip the unmarked grids. */
#define MP_SAMPLE_DEPTH 0u
#define MP_SAMPLE_ATTRIBUTES 1u
#define MP_SAMPLE_OPAQUE_DEPTH 2u
#define MP_SAMPLE_MARK 3u
#define MP_SAMPLE_KIND 3u
#define MP_SAMPLE_AFTER_MARK 4u

MP_INLINE uint mp_sample_offset_packed(int tx, int ty, int s, FrameParams f) {
  /* Blurred, slot s is a time or lens stratum (mp_blur.h); its position
   * stratum is shuffled per pixel so the two do not follow each other. */
  int p = mp_blur_on(f) ? (int)mp_permute((uint)s, (uint)(f.spp_x * f.spp_y),
                                          mp_hash_combine(mp_hash32((uint)tx ^ f.seed), (uint)ty))
                        : s;
  int sx = p % f.spp_x, sy = p / f.spp_x;
  uint h = mp_hash_combine(mp_hash_combine(mp_hash32((uint)tx ^ f.seed), (uint)ty), (uint)s);
  float jx = mp_hash_unit(h), jy = mp_hash_unit(mp_hash32(h));
  uint ox = (uint)(((float)sx + jx) / (float)f.spp_x * (float)MP_SUBPIXEL_ONE);
  uint oy = (uint)(((float)sy + jy) / (float)f.spp_y * (float)MP_SUBPIXEL_ONE);
  return (ox < 255u ? ox : 255u) | ((oy < 255u ? oy : 255u) << 8);
}

MP_INLINE MpFixed2 mp_sample_position(int px, int py, int s, int spp, FrameParams f, const MP_GLOBAL ushort* offsets) {
  int tx = (px + f.crop_x0) & (MP_SAMPLE_TILE - 1), ty = (py + f.crop_y0) & (MP_SAMPLE_TILE - 1);
  uint o = offsets[(ty * MP_SAMPLE_TILE + tx) * spp + s];
  MpFixed2 p;
  p.x = (long)px * MP_SUBPIXEL_ONE + (long)(o & 0xffu);
  p.y = (long)py * MP_SUBPIXEL_ONE + (long)(o >> 8);
  return p;
}

/* A raster position of the whole crop region's frame (FrameParams.frame_bx)
 * in fixed point in the sample buffer, whose origin is its bucket's. */
MP_INLINE MpFixed2 mp_sample_fixed(float rx, float ry, FrameParams f) {
  MpFixed2 q;
  q.x = mp_to_fixed(rx) - ((long)f.bucket_x0 << MP_SUBPIXEL_BITS);
  q.y = mp_to_fixed(ry) - ((long)f.bucket_y0 << MP_SUBPIXEL_BITS);
  return q;
}

/* Twice the signed area of (a, b, p); in raster space (y down) a triangle whose
 * vertices run counter-clockwise on screen has a negative area. */
MP_INLINE long mp_edge(MpFixed2 a, MpFixed2 b, MpFixed2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/* Tie rule for samples exactly on an edge: of the two directions an edge can
 * be walked in, exactly one owns it, so triangles sharing an edge never both
 * (or neither) cover a sample on it. */
MP_INLINE int mp_edge_owns(MpFixed2 a, MpFixed2 b) {
  long dx = b.x - a.x, dy = b.y - a.y;
  return dy > 0 || (dy == 0 && dx < 0);
}

MP_INLINE int mp_edge_inside(long e, int owns) { return e > 0 || (e == 0 && owns); }

/* A triangle set up for coverage tests: vertices ordered so that inside
 * means all three edge functions >= 0 (with the tie rule on ties); `swapped`
 * tells the caller that b and c were exchanged to get there. */
typedef struct {
  MpFixed2 a, b, c;
  int own0, own1, own2;
  float inv_area;
  int valid, swapped;
} MpEdgeTriangle;

MP_INLINE MpEdgeTriangle mp_edge_triangle(MpFixed2 a, MpFixed2 b, MpFixed2 c) {
  MpEdgeTriangle t;
  long area = mp_edge(a, b, c);
  t.valid = area != 0;
  t.swapped = area > 0; /* make the orientation uniform; culling happened before */
  if (t.swapped) {
    MpFixed2 tmp = b;
    b = c;
    c = tmp;
    area = -area;
  }
  t.a = a;
  t.b = b;
  t.c = c;
  t.own0 = mp_edge_owns(b, c);
  t.own1 = mp_edge_owns(c, a);
  t.own2 = mp_edge_owns(a, b);
  t.inv_area = t.valid ? 1.0f / (float)(-area) : 0.0f;
  return t;
}

/* Barycentrics (of a, b, c as ordered in t) of q if the triangle covers it. */
MP_INLINE int mp_edge_triangle_covers(const MpEdgeTriangle* t, MpFixed2 q, float* la, float* lb, float* lc) {
  if (!t->valid) return 0;
  long e0 = -mp_edge(t->b, t->c, q), e1 = -mp_edge(t->c, t->a, q), e2 = -mp_edge(t->a, t->b, q);
  if (!(mp_edge_inside(e0, t->own0) && mp_edge_inside(e1, t->own1) && mp_edge_inside(e2, t->own2))) return 0;
  *la = (float)e0 * t->inv_area;
  *lb = (float)e1 * t->inv_area;
  *lc = (float)e2 * t->inv_area;
  return 1;
}

/* Octahedral encoding of a unit vector into 2 x 16 bits (Cigolle et al. 2014). */
MP_INLINE uint mp_encode_normal(float3 n) {
  float s = fabs(n.x) + fabs(n.y) + fabs(n.z);
  if (!(s > 0.0f)) return 0x7fff7fffu;
  float x = n.x / s, y = n.y / s;
  if (n.z < 0.0f) {
    float ox = (1.0f - fabs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    float oy = (1.0f - fabs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
    x = ox;
    y = oy;
  }
  uint qx = (uint)clamp((int)floor((x * 0.5f + 0.5f) * 65535.0f + 0.5f), 0, 65535);
  uint qy = (uint)clamp((int)floor((y * 0.5f + 0.5f) * 65535.0f + 0.5f), 0, 65535);
  return qx | (qy << 16);
}

MP_INLINE float3 mp_decode_normal(uint e) {
  float x = (float)(e & 0xffffu) / 65535.0f * 2.0f - 1.0f;
  float y = (float)(e >> 16) / 65535.0f * 2.0f - 1.0f;
  float z = 1.0f - fabs(x) - fabs(y);
  if (z < 0.0f) {
    float ox = (1.0f - fabs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    float oy = (1.0f - fabs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
    x = ox;
    y = oy;
  }
  float3 n = MP_F3(x, y, z);
  return n / length(n);
}

/* Pixel filters with RenderMan's conventions (RiBoxFilter, RiTriangleFilter,
 * RiGaussianFilter); width is the full support in pixels. */
#define MP_FILTER_BOX 0
#define MP_FILTER_GAUSSIAN 1
#define MP_FILTER_TRIANGLE 2
#define MP_FILTER_BLACKMAN_HARRIS 3

/* Blackman-Harris window over [-width/2, width/2] (Harris 1978), the pixel
 * filter Cycles uses by default; separable. */
MP_INLINE float mp_blackman_harris(float x, float width) {
  float t = 2.0f * 3.14159265f * (x / width + 0.5f);
  return 0.35875f - 0.48829f * cos(t) + 0.14128f * cos(2.0f * t) - 0.01168f * cos(3.0f * t);
}

/* Pixels a side of the tiled resolve's work-groups (resolve.cl, ResolveStage). */
#define MP_RESOLVE_TILE 8

/* Pixels on each side whose samples a pixel filter of this full width
 * reads (the resolve's neighbourhood; a bucket's margin). */
MP_INLINE int mp_filter_reach(float width) {
  int r = (int)ceil(0.5f * width - 0.5f);
  return r > 0 ? r : 0;
}

MP_INLINE float mp_filter_weight(int type, float x, float y, float width) {
  float h = 0.5f * width;
  if (fabs(x) > h || fabs(y) > h) return 0.0f;
  if (type == MP_FILTER_GAUSSIAN) {
    float sx = x / h, sy = y / h;
    return exp(-2.0f * (sx * sx + sy * sy));
  }
  if (type == MP_FILTER_TRIANGLE) return (1.0f - fabs(x) / h) * (1.0f - fabs(y) / h);
  if (type == MP_FILTER_BLACKMAN_HARRIS) return mp_blackman_harris(x, width) * mp_blackman_harris(y, width);
  return 1.0f;
}

#endif
