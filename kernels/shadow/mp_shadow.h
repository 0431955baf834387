/* Shadow maps: virtual, paged depth maps of each light, rendered by the
 * micropolygon pipeline itself (RenderMan's shadow maps, in the paged form
 * of Unreal's virtual shadow maps), and their lookups while shading.
 *
 * Every light that casts shadows is a set of virtual maps of 16384 x 16384
 * texels, cut into pages of 128 x 128 texels that exist only where a
 * receiver the camera sees needs them:
 *
 *  - a sun: clipmap levels, orthographic along the light, level l with
 *    texels of 2^l scene units, each a window of 128 x 128 pages around the
 *    camera whose page table wraps around (a page keeps its slot while the
 *    camera moves);
 *  - a point, spot or area light: the six faces of a cube around the light
 *    (90 degree perspective views), each with mips m = 0..7 of 16384 >> m
 *    texels.
 *
 * A receiver at camera depth d covers a pixel of d / max(|ax|, |ay|) scene
 * units (the pixel footprint); it reads the level (or mip) whose texels are
 * no larger than that, so shadow detail follows the screen. A coarse pass of
 * the camera's bound & split marks the pages its sub-patches need
 * (shadow.cl); the host gives them physical pages from a pool of fixed size
 * (the shadow memory budget) and the light's views render them.
 *
 * Filtering compares each texel with the receiver's tangent plane where the
 * texel's ray meets it (receiver-plane depth, so a tilted receiver does not
 * shadow itself), bilinearly; soft shadows estimate the occluders' distance
 * from the texels in a search region and filter over the light's shape
 * scaled by it (percentage-closer soft shadows, Fernando 2005), which widens
 * the penumbra with the distance from the occluder as an area light's does.
 *
 * Shared by the kernels (shadow.cl, shade.cl, material programs) and the
 * host (pipeline/shadows/shadow_maps.cpp, tests), so both agree on every index. */
#ifndef MP_SHADOW_H
#define MP_SHADOW_H

#include "core/mp_compat.h"
#include "core/mp_hash.h"
#include "core/mp_types.h"

#define MP_PAGE_SIZE 128          /* texels per page side */
#define MP_PAGE_TEXELS 16384      /* texels per page */
#define MP_MAP_PAGES 128          /* pages per side of a full virtual map */
#define MP_MAP_TEXELS 16384       /* texels per side of a full virtual map */
#define MP_CUBE_MIPS 8            /* 16384 down to one page */
#define MP_CUBE_FACE_ENTRIES 21845 /* page-table entries of one face, all mips */
#define MP_MAX_SUN_LEVELS 24

/* A page-table entry: the physical page in the pool, whether the page holds
 * depths (resident) and whether this frame's shadow pass renders it. */
#define MP_PAGE_RESIDENT 0x80000000u
#define MP_PAGE_RENDER 0x40000000u
#define MP_PAGE_PHYSICAL(e) ((e) & 0x3fffffffu)
/* A texel no surface covers (+infinity as float bits: never in front). */
#define MP_SHADOW_EMPTY 0x7f800000u

/* Texels per side of cube mip m, and the table entries before it in a face. */
MP_INLINE int mp_cube_mip_texels(int m) { return MP_MAP_TEXELS >> m; }
MP_INLINE uint mp_cube_mip_entries(int m) {
  /* sum over k < m of (128 >> k)^2 = 16384 (1 - 4^-m) / (3/4) */
  return (65536u - (65536u >> (2 * m))) / 3u;
}

/* The cube face a light-space direction falls on: +X, -X, +Y, -Y, +Z, -Z. */
MP_INLINE int mp_cube_face(float3 q) {
  float ax = fabs(q.x), ay = fabs(q.y), az = fabs(q.z);
  if (ax >= ay && ax >= az) return q.x >= 0.0f ? 0 : 1;
  if (ay >= az) return q.y >= 0.0f ? 2 : 3;
  return q.z >= 0.0f ? 4 : 5;
}

/* Light space -> the face's view space (a rotation; the face looks down -Z):
 * with a the face's axis and s its sign, (x, y, z) = (-s q[a+1], q[a+2], -s q[a]). */
MP_INLINE float3 mp_cube_face_view(int face, float3 q) {
  int a = face >> 1;
  float s = (face & 1) ? -1.0f : 1.0f;
  float qa = a == 0 ? q.x : a == 1 ? q.y : q.z;
  float q1 = a == 0 ? q.y : a == 1 ? q.z : q.x;
  float q2 = a == 0 ? q.z : a == 1 ? q.x : q.y;
  return MP_F3(-s * q1, q2, -s * qa);
}

/* Its inverse. */
MP_INLINE float3 mp_cube_face_unview(int face, float3 v) {
  int a = face >> 1;
  float s = (face & 1) ? -1.0f : 1.0f;
  float qa = -s * v.z, q1 = -s * v.x, q2 = v.y;
  return a == 0 ? MP_F3(qa, q1, q2) : a == 1 ? MP_F3(q2, qa, q1) : MP_F3(q1, q2, qa);
}

MP_INLINE float3 mp_xform_point(const MP_GLOBAL float* m, float3 p) {
  return MP_F3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
               m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

MP_INLINE float3 mp_xform_dir(const MP_GLOBAL float* m, float3 v) {
  return MP_F3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
               m[8] * v.x + m[9] * v.y + m[10] * v.z);
}

/* Scene units covered by one pixel at camera depth d (orthographic: any d). */
MP_INLINE float mp_pixel_footprint(float d, FrameParams f) {
  float scale = fmax(fabs(f.ax), fabs(f.ay));
  return (f.ortho ? 1.0f : d) / scale;
}

/* floor(log2(x)) for x > 0, from the float's exponent, so every device and
 * the host agree exactly (log2 may differ in the last place). */
MP_INLINE int mp_floor_log2(float x) {
  uint b = as_uint(x);
  int e = (int)((b >> 23) & 0xffu);
  if (e == 0) return -127;
  return e - 127;
}

MP_INLINE int mp_ceil_log2(float x) {
  int l = mp_floor_log2(x);
  uint b = as_uint(x);
  return (b & 0x7fffffu) ? l + 1 : l;
}

/* Level (sun) of the finest clipmap whose texels are no larger than the
 * footprint, before the light's bias and clamping. */
MP_INLINE int mp_sun_level_for(float footprint) { return mp_floor_log2(footprint); }

/* Mip of a cube face whose texels, at face depth z, are no larger than the
 * footprint: texel = z * 2^(m+1) / 16384. */
MP_INLINE int mp_cube_mip_for(float footprint, float z) {
  return mp_floor_log2(footprint * (float)(MP_MAP_TEXELS / 2) / fmax(z, 1e-30f));
}

/* Raster rectangle (texels of a face `texels` wide) onto which the part of
 * the light-space box [lo, hi] inside the face's frustum projects; 0 when
 * that part is empty. Points in a face's frustum have depth >= |x|, |y| in
 * its view, which bounds the depths that matter for boxes beside the light. */
MP_INLINE int mp_cube_face_box(int face, float3 lo, float3 hi, float texels, float* x0, float* y0, float* x1,
                               float* y1) {
  float3 a = mp_cube_face_view(face, lo), b = mp_cube_face_view(face, hi);
  float3 vlo = fmin(a, b), vhi = fmax(a, b);
  float mx = vlo.x > 0.0f ? vlo.x : vhi.x < 0.0f ? -vhi.x : 0.0f;
  float my = vlo.y > 0.0f ? vlo.y : vhi.y < 0.0f ? -vhi.y : 0.0f;
  float dhi = -vlo.z, dlo = fmax(fmax(-vhi.z, fmax(mx, my)), 1e-30f);
  if (!(dhi > 0.0f) || dlo > dhi) return 0;
  float umin = vlo.x >= 0.0f ? vlo.x / dhi : vlo.x / dlo, umax = vhi.x >= 0.0f ? vhi.x / dlo : vhi.x / dhi;
  float wmin = vlo.y >= 0.0f ? vlo.y / dhi : vlo.y / dlo, wmax = vhi.y >= 0.0f ? vhi.y / dlo : vhi.y / dhi;
  if (umin > 1.0f || umax < -1.0f || wmin > 1.0f || wmax < -1.0f) return 0;
  float h = 0.5f * texels;
  *x0 = (fmax(umin, -1.0f) + 1.0f) * h;
  *x1 = (fmin(umax, 1.0f) + 1.0f) * h;
  *y0 = (fmax(wmin, -1.0f) + 1.0f) * h;
  *y1 = (fmin(wmax, 1.0f) + 1.0f) * h;
  return 1;
}

/* One map of a light, as lookups see it. */
typedef struct {
  uint table;        /* first page-table entry */
  int side;          /* pages per side */
  int origin_x, origin_y;
  int face;          /* cube face, or -1 for a sun level */
  float scale;       /* sun: texels per scene unit; cube: texels per unit of x/d, half the side */
  float off_x, off_y, z_top;
} MpShadowMap;

typedef struct {
  const MP_GLOBAL DeviceShadow* shadows; /* one per light (kind MP_SHADOW_NONE for lights without) */
  const MP_GLOBAL DeviceShadowLevel* levels;
  const MP_GLOBAL uint* pages;  /* page tables */
  const MP_GLOBAL uint* pool;   /* physical pages, MP_PAGE_TEXELS float depths each */
} MpShadowMaps;

#ifdef __OPENCL_VERSION__
/* The shadow maps as shading kernels take them, in the order the host's
 * ShadowInputs::args() binds them: whether shadows are on, then the maps. */
#define MP_SHADOW_INPUT_PARAMS                                                                                  \
  uint use_shadows, __global const DeviceShadow *shadows, __global const DeviceShadowLevel *shadow_levels,     \
      __global const uint *shadow_pages, __global const uint *shadow_pool
#define MP_SHADOW_INPUTS {shadows, shadow_levels, shadow_pages, shadow_pool}
#endif

MP_INLINE MpShadowMap mp_sun_map(const MP_GLOBAL DeviceShadow* sh, const MP_GLOBAL DeviceShadowLevel* lv) {
  MpShadowMap m;
  m.table = lv->page_table;
  m.side = MP_MAP_PAGES;
  m.origin_x = lv->origin_x;
  m.origin_y = lv->origin_y;
  m.face = -1;
  m.scale = 1.0f / lv->texel;
  m.off_x = lv->offset[0];
  m.off_y = lv->offset[1];
  m.z_top = sh->z_top;
  return m;
}

MP_INLINE MpShadowMap mp_cube_map(const MP_GLOBAL DeviceShadow* sh, int face, int mip) {
  MpShadowMap m;
  m.table = sh->page_table + (uint)face * MP_CUBE_FACE_ENTRIES + mp_cube_mip_entries(mip);
  m.side = MP_MAP_PAGES >> mip;
  m.origin_x = m.origin_y = 0;
  m.face = face;
  m.scale = 0.5f * (float)mp_cube_mip_texels(mip);
  m.off_x = m.off_y = m.z_top = 0.0f;
  return m;
}

/* Raster position (texels) and view depth of light-space point q. */
MP_INLINE float3 mp_shadow_project(const MpShadowMap* m, float3 q) {
  if (m->face < 0) return MP_F3((q.x + m->off_x) * m->scale, (q.y + m->off_y) * m->scale, m->z_top - q.z);
  float3 v = mp_cube_face_view(m->face, q);
  float d = -v.z;
  return MP_F3((v.x / d + 1.0f) * m->scale, (v.y / d + 1.0f) * m->scale, d);
}

/* Scene units one texel of the map covers at view depth d. */
MP_INLINE float mp_shadow_texel_size(const MpShadowMap* m, float d) {
  return m->face < 0 ? 1.0f / m->scale : d / m->scale;
}

/* The receiver's tangent plane (through q, normal n, light space) as one
 * map sees it: the view depth where the ray of raster point (x, y) meets it
 * is a + b x + c y for a sun's level (orthographic), and its reciprocal is
 * for a cube face (a plane's points have 1 / depth linear in the
 * projection). Where the rays run along the plane (or miss it), the depth
 * is the receiver's own. */
typedef struct {
  float a, b, c;
  int reciprocal;
} MpReceiverPlane;

MP_INLINE MpReceiverPlane mp_receiver_plane(const MpShadowMap* m, float3 q, float3 n, float qdepth) {
  MpReceiverPlane p;
  p.reciprocal = 0;
  p.a = qdepth;
  p.b = p.c = 0.0f;
  if (m->face < 0) {
    if (!(fabs(n.z) > 1e-6f)) return p;
    float k = 1.0f / (n.z * m->scale);
    p.b = n.x * k;
    p.c = n.y * k;
    p.a = m->z_top - q.z - (n.x * (m->off_x + q.x) + n.y * (m->off_y + q.y)) / n.z;
    return p;
  }
  float nq = dot(n, q);
  if (!(fabs(nq) > 1e-12f)) return p;
  /* the ray direction at (x, y), unview(x / scale - 1, y / scale - 1, -1), is linear in x and y */
  float d0 = dot(n, mp_cube_face_unview(m->face, MP_F3(-1.0f, -1.0f, -1.0f)));
  float dx = dot(n, mp_cube_face_unview(m->face, MP_F3(1.0f, 0.0f, 0.0f))) / m->scale;
  float dy = dot(n, mp_cube_face_unview(m->face, MP_F3(0.0f, 1.0f, 0.0f))) / m->scale;
  p.reciprocal = 1;
  p.a = d0 / nq;
  p.b = dx / nq;
  p.c = dy / nq;
  return p;
}

MP_INLINE float mp_plane_depth(const MpReceiverPlane* p, float x, float y, float fallback) {
  float v = p->a + p->b * x + p->c * y;
  if (!p->reciprocal) return v;
  return v > 0.0f ? 1.0f / v : fallback;
}

/* The physical page holding texel (ix, iy) of the map, or -1 when it is not
 * resident. A cube face's filters that reach past its edge read its edge
 * texels (the neighbouring face's first ones see nearly the same); outside
 * a clipmap level's window there is nothing (a coarser level covers it). */
MP_INLINE long mp_shadow_page(const MpShadowMaps* in, const MpShadowMap* m, int* ix, int* iy) {
  int texels = m->side * MP_PAGE_SIZE;
  if (m->face >= 0) {
    *ix = clamp(*ix, 0, texels - 1);
    *iy = clamp(*iy, 0, texels - 1);
  }
  if (*ix < 0 || *iy < 0 || *ix >= texels || *iy >= texels) return -1;
  int sx = ((*ix >> 7) + m->origin_x) & (m->side - 1), sy = ((*iy >> 7) + m->origin_y) & (m->side - 1);
  uint e = in->pages[m->table + (uint)(sy * m->side + sx)];
  return (e & MP_PAGE_RESIDENT) ? (long)MP_PAGE_PHYSICAL(e) : -1;
}

/* Depth stored at texel (ix, iy) of the map; 0 when its page is not resident. */
MP_INLINE int mp_shadow_texel(const MpShadowMaps* in, const MpShadowMap* m, int ix, int iy, float* depth) {
  long page = mp_shadow_page(in, m, &ix, &iy);
  if (page < 0) return 0;
  *depth = as_float(in->pool[(ulong)page * MP_PAGE_TEXELS + (ulong)((iy & 127) * MP_PAGE_SIZE + (ix & 127))]);
  return 1;
}

/* The 2 x 2 texels around raster point (x, y): their depths, their centres'
 * receiver-plane depths and their bilinear weights; 0 when a page is not
 * resident. */
MP_INLINE int mp_shadow_quad(const MpShadowMaps* in, const MpShadowMap* m, const MpReceiverPlane* plane, float x,
                             float y, float fallback, float* d, float* r, float* w) {
  float fx = x - 0.5f, fy = y - 0.5f;
  float bx = floor(fx), by = floor(fy);
  int ix = (int)bx, iy = (int)by;
  float wx = fx - bx, wy = fy - by;
  /* One page lookup when the four texels share a page (most do). */
  int jx = ix, jy = iy;
  long page = -1;
  int same = ix >= 0 && iy >= 0 && (ix & 127) != 127 && (iy & 127) != 127;
  if (same) {
    page = mp_shadow_page(in, m, &jx, &jy);
    same = jx == ix && jy == iy;
  }
  for (int k = 0; k < 4; ++k) {
    int tx = ix + (k & 1), ty = iy + (k >> 1);
    if (same) {
      if (page < 0) return 0;
      d[k] = as_float(in->pool[(ulong)page * MP_PAGE_TEXELS + (ulong)((ty & 127) * MP_PAGE_SIZE + (tx & 127))]);
    } else if (!mp_shadow_texel(in, m, tx, ty, &d[k])) {
      return 0;
    }
    r[k] = mp_plane_depth(plane, (float)tx + 0.5f, (float)ty + 0.5f, fallback);
    w[k] = ((k & 1) ? wx : 1.0f - wx) * ((k >> 1) ? wy : 1.0f - wy);
  }
  return 1;
}

/* Fraction of the bilinear footprint around raster point (x, y) that sees
 * the light from the receiver plane; *missing when a texel's page is not
 * resident. Each texel is compared with the plane's depth on its own ray,
 * less `bias` (scene units). */
MP_INLINE float mp_shadow_bilinear(const MpShadowMaps* in, const MpShadowMap* m, const MpReceiverPlane* plane, float x,
                                   float y, float fallback, float bias, int* missing) {
  float d[4], r[4], w[4];
  if (!mp_shadow_quad(in, m, plane, x, y, fallback, d, r, w)) {
    *missing = 1;
    return 1.0f;
  }
  float lit = 0.0f;
  for (int k = 0; k < 4; ++k)
    if (r[k] - bias <= d[k]) lit += w[k];
  return lit;
}

/* The texel nearest raster point (x, y): whether it holds an occluder in
 * front of the receiver plane by more than `bias` whose occluder-to-receiver
 * ratio (mp_kernel_point: the depth difference for suns, over the occluder's
 * depth for local lights) is at least min_ratio; the ratio in *ratio. */
MP_INLINE int mp_shadow_blocker(const MpShadowMaps* in, const MpShadowMap* m, const MpReceiverPlane* plane, float x,
                                float y, float fallback, float bias, int sun, float min_ratio, float* ratio,
                                int* missing) {
  int ix = (int)floor(x), iy = (int)floor(y);
  float d;
  if (!mp_shadow_texel(in, m, ix, iy, &d)) {
    *missing = 1;
    return 0;
  }
  float r = mp_plane_depth(plane, (float)ix + 0.5f, (float)iy + 0.5f, fallback);
  if (!(r - bias > d)) return 0;
  *ratio = sun ? r - d : (r - d) / fmax(d, 1e-20f);
  return *ratio >= min_ratio;
}

/* Depth bias in texels of the map at the receiver. The receiver plane takes
 * care of a flat receiver's slope; the bias covers the rest: the shadow
 * view's micropolygons and the camera's sample the surface at other points,
 * and a curved surface leaves its tangent plane by a distance that, seen
 * along a grazing light, grows as the light lowers. So a constant part and
 * one that grows with the tangent of the light's angle to the normal. */
#define MP_SHADOW_BIAS_TEXELS 0.5f
#define MP_SHADOW_SLOPE_BIAS_TEXELS 0.5f
#define MP_SHADOW_MAX_SLOPE 8.0f
/* Soft shadows' taps lie off the receiver, where its tangent plane leaves
 * a curved surface: their bias grows by this fraction of their distance. */
#define MP_SHADOW_SOFT_BIAS 0.05f
/* Taps of the blocker search's first round (which most receivers, seeing
 * no occluder, end with), of its second round and of the soft filter. */
#define MP_SHADOW_PROBE_TAPS 8
#define MP_SHADOW_TAPS 16
/* The blocker search reaches occluders up to halfway from the receiver to a
 * local light (the search kernel is the light's shape scaled by f / (1 - f)
 * for a fraction f of the way). */
#define MP_SHADOW_SEARCH_SCALE 1.0f
/* Texels across the search and filter kernels' radius. */
#define MP_SHADOW_SEARCH_TEXELS 8.0f
#define MP_SHADOW_FILTER_TEXELS 4.0f

/* Taps over the unit disk follow Vogel's spiral (even density, no two taps
 * on one ray): tap k at radius sqrt((k + 1/2) / n), turned by k golden
 * angles. Loops step the turn by a fixed rotation (no sine or cosine per
 * tap). */
#define MP_GOLDEN_COS -0.73736887f
#define MP_GOLDEN_SIN 0.67549029f
MP_INLINE float2 mp_golden_step(float2 turn) {
  return MP_F2(turn.x * MP_GOLDEN_COS - turn.y * MP_GOLDEN_SIN, turn.x * MP_GOLDEN_SIN + turn.y * MP_GOLDEN_COS);
}
/* Two golden angles. */
#define MP_GOLDEN2_COS 0.08742572f
#define MP_GOLDEN2_SIN -0.99617104f
MP_INLINE float2 mp_golden_step2(float2 turn) {
  return MP_F2(turn.x * MP_GOLDEN2_COS - turn.y * MP_GOLDEN2_SIN, turn.x * MP_GOLDEN2_SIN + turn.y * MP_GOLDEN2_COS);
}

/* The light's shape as two offset vectors from its centre: a point d of the
 * unit disk (or square, for rectangles) lies at d.x u + d.y v, in light space
 * (local lights) or in the light's xy plane as tangents of the angle (suns).
 * Point and spot lights are disks facing the receiver's direction `toward`;
 * area lights lie in the light's plane. */
typedef struct {
  float3 u, v;
  int grid; /* a rectangle: filter taps on a 4 x 4 grid */
} MpLightShape;

MP_INLINE MpLightShape mp_light_shape(const MP_GLOBAL DeviceShadow* sh, float3 toward) {
  MpLightShape s;
  s.grid = sh->shape == MP_SHADOW_SHAPE_RECTANGLE;
  if (sh->shape == MP_SHADOW_SHAPE_RECTANGLE || sh->shape == MP_SHADOW_SHAPE_ELLIPSE) {
    s.u = MP_F3(sh->size[0], 0.0f, 0.0f);
    s.v = MP_F3(0.0f, sh->size[1], 0.0f);
  } else if (sh->kind == MP_SHADOW_SUN) {
    s.u = MP_F3(sh->size[0], 0.0f, 0.0f);
    s.v = MP_F3(0.0f, sh->size[0], 0.0f);
  } else {
    float3 w = normalize(toward);
    float3 a = fabs(w.x) < 0.9f ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f);
    float3 u = normalize(cross(w, a));
    s.u = sh->size[0] * u;
    s.v = sh->size[0] * cross(w, u);
  }
  return s;
}

/* Filter tap i of MP_SHADOW_TAPS (16), even density over the shape, in an
 * order whose first half is itself spread evenly (the filter stops there
 * where all its taps agree). Over a disk Vogel's spiral, tap k at radius
 * sqrt((k + 1/2) / 16), taken even k first, then odd (`turn` is tap k's
 * rotation, k golden angles); over a rectangle the 16 Hammersley points (x =
 * (k + 1/2) / 16, y its bit-reversed twin), which, unlike a 4 x 4 grid, take
 * 16 different values along each side, so a shadow edge along either sweeps
 * through 16 steps rather than 4, taken those with an even number of set
 * bits first (which alone are a (0, 3, 2)-net: one in each eighth of either
 * side, two in each quarter of the square). */
MP_INLINE float3 mp_filter_tap(const MpLightShape* s, int i, float2 turn, float2 shift) {
  int h = i & 7, odd = i >> 3;
  if (s->grid) {
    int parity = (h ^ (h >> 1) ^ (h >> 2)) & 1;
    int k = 2 * h + (parity ^ odd);
    int rev = ((k & 1) << 3) | ((k & 2) << 1) | ((k & 4) >> 1) | ((k & 8) >> 3);
    float x = ((float)k + 0.5f) * (1.0f / 16.0f) + shift.x, y = ((float)rev + 0.5f) * (1.0f / 16.0f) + shift.y;
    x = 2.0f * (x - floor(x)) - 1.0f;
    y = 2.0f * (y - floor(y)) - 1.0f;
    return x * s->u + y * s->v;
  }
  float r = sqrt(((float)(2 * h + odd) + 0.5f) * (1.0f / 16.0f));
  return (r * turn.x) * s->u + (r * turn.y) * s->v;
}

/* Each receiver turns the filter's spiral by its own angle (and shifts its
 * Hammersley points, wrapping around the square), from a hash of its
 * position: neighbouring receivers then make uncorrelated errors, fine
 * noise that the pixel samples average, rather than the same error over a
 * region (blotches). The blocker search keeps one pattern for all: turned
 * per receiver, it found a receiver's own curved surface at some points
 * and not at their neighbours (speckles on curved lit surfaces). */
MP_INLINE float2 mp_filter_spin(float3 q, float2* shift) {
  uint h = mp_hash_combine(mp_hash_combine(mp_hash32(as_uint(q.x)), as_uint(q.y)), as_uint(q.z));
  float a = 6.28318531f * mp_hash_unit(h);
  *shift = MP_F2(mp_hash_unit(mp_hash32(h)), mp_hash_unit(mp_hash32(h ^ 0x5bd1e995u)));
  return MP_F2(cos(a), sin(a));
}

/* Which of the two filter levels tap i reads: the coarser where this falls
 * below the kernel's fraction of the way to it (the golden ratio's
 * multiples, spread evenly over the taps in any run of them). */
MP_INLINE float mp_tap_dither(int i) {
  float t = ((float)i + 0.5f) * 0.61803399f;
  return t - floor(t);
}

/* Blocker search tap k of n: from the shape's centre (k = 0) out to its edge
 * at even steps of radius, so that the small regions where occluders near
 * the receiver can stand get taps too; *reach is the radius (0..1). */
MP_INLINE float3 mp_search_tap(const MpLightShape* s, int k, int n, float2 turn, float* reach) {
  float r = n > 1 ? (float)k / (float)(n - 1) : 0.0f;
  *reach = r;
  return (r * turn.x) * s->u + (r * turn.y) * s->v;
}

/* Radius of the light's shape (the search and filter kernels' extent). */
MP_INLINE float mp_light_shape_radius(const MP_GLOBAL DeviceShadow* sh) {
  if (sh->shape == MP_SHADOW_SHAPE_RECTANGLE) return sqrt(sh->size[0] * sh->size[0] + sh->size[1] * sh->size[1]);
  return fmax(sh->size[0], sh->size[1]);
}

/* The map of a light that point q falls on at detail `level` (sun: level
 * index from level0; cube: mip). */
MP_INLINE MpShadowMap mp_shadow_map_at(const MpShadowMaps* in, const MP_GLOBAL DeviceShadow* sh, float3 q, int level) {
  if (sh->kind == MP_SHADOW_SUN) return mp_sun_map(sh, in->levels + sh->level_records + (uint)level);
  return mp_cube_map(sh, mp_cube_face(q), level);
}

/* The same for a loop's taps, all at one level: a sun's level is the same
 * map for all, a cube's map changes only where a tap crosses to another
 * face (`m` holds the last tap's). */
MP_INLINE void mp_shadow_map_for(const MpShadowMaps* in, const MP_GLOBAL DeviceShadow* sh, float3 q, int level,
                                 int first, MpShadowMap* m) {
  if (sh->kind == MP_SHADOW_SUN) {
    if (first) *m = mp_sun_map(sh, in->levels + sh->level_records + (uint)level);
    return;
  }
  int face = mp_cube_face(q);
  if (first || face != m->face) *m = mp_cube_map(sh, face, level);
}

MP_INLINE int mp_shadow_level_count(const MP_GLOBAL DeviceShadow* sh) {
  return sh->kind == MP_SHADOW_SUN ? (int)sh->levels : MP_CUBE_MIPS;
}

/* The level whose texels (at q) are about `size` scene units over `texels`,
 * no finer than `finest`. */
MP_INLINE int mp_shadow_level_for_size(const MP_GLOBAL DeviceShadow* sh, float3 q, float size, float texels, int finest) {
  int count = mp_shadow_level_count(sh);
  float per = size / texels;
  int l;
  if (sh->kind == MP_SHADOW_SUN) {
    l = mp_ceil_log2(fmax(per, 1e-30f)) - sh->level0;
  } else {
    float3 a = MP_F3(fabs(q.x), fabs(q.y), fabs(q.z));
    float z = fmax(a.x, fmax(a.y, a.z));
    l = mp_ceil_log2(fmax(per * (float)(MP_MAP_TEXELS / 2) / fmax(z, 1e-30f), 1e-30f));
  }
  return clamp(max(l, finest), 0, count - 1);
}

/* The bias of a receiver at q with normal n (light space), in texels. */
MP_INLINE float mp_shadow_bias_texels(const MP_GLOBAL DeviceShadow* sh, float3 q, float3 n) {
  float ln = length(n);
  float c = !(ln > 0.0f) ? 1.0f : sh->kind == MP_SHADOW_SUN ? n.z / ln : dot(n, q) / (ln * fmax(length(q), 1e-30f));
  c = fmax(fabs(c), 1e-3f);
  float t = fmin(sqrt(fmax(1.0f - c * c, 0.0f)) / c, MP_SHADOW_MAX_SLOPE);
  return MP_SHADOW_BIAS_TEXELS + MP_SHADOW_SLOPE_BIAS_TEXELS * t;
}

/* Level a receiver at q reads for hard shadows, from its pixel footprint. */
MP_INLINE int mp_shadow_base_level(const MP_GLOBAL DeviceShadow* sh, float3 q, float footprint) {
  int l;
  if (sh->kind == MP_SHADOW_SUN) {
    l = mp_sun_level_for(footprint) + sh->level_bias - sh->level0;
  } else {
    float3 a = MP_F3(fabs(q.x), fabs(q.y), fabs(q.z));
    l = mp_cube_mip_for(footprint, fmax(a.x, fmax(a.y, a.z))) + sh->level_bias;
  }
  return clamp(l, 0, mp_shadow_level_count(sh) - 1);
}

/* Point q + offset * scale of a kernel over the light's shape: local lights
 * scale their shape by (receiver - occluder) / occluder along the ray, the
 * sun its angle's tangent by the occluder's height above the receiver. */
MP_INLINE float3 mp_kernel_point(float3 q, float3 offset, float scale) { return q + offset * scale; }

/* The receiver plane of map m, kept while taps stay on one map (a map is
 * known by its page table's start). */
MP_INLINE void mp_plane_for(const MpShadowMap* m, float3 q, float3 n, float qdepth, uint* map, MpReceiverPlane* plane) {
  if (*map != m->table) {
    *plane = mp_receiver_plane(m, q, n, qdepth);
    *map = m->table;
  }
}

/* The blocker search runs in two rounds. The first looks for occluders
 * between the receiver and (local lights) halfway to the light, or (suns)
 * the top of the scene; it tells whether any stands near at all and how far
 * off they are on average. It reads a level whose texels suit its
 * region, and an occluder smaller than those texels (a leaf under a sun
 * over a large ground) may cover none of their centres; so where it finds
 * none, one tap looks straight at the light from the receiver at the
 * receiver's own level, which sees any occluder whose shadow's core covers
 * the receiver. The second round searches again over the region those
 * can shadow (twice their mean scale), where its taps lie denser, and
 * counts only occluders that stand between the receiver and the light: a
 * tap at the shape's offset O scaled by s that finds an occluder of scale
 * (distance ratio, mp_kernel_point) r blocks the light point O s / r,
 * which is on the light only if r >= s * reach. Occluders off to the side
 * would only widen the penumbra estimate (the classic fault of
 * percentage-closer soft shadows). */
MP_INLINE float mp_first_search_scale(const MP_GLOBAL DeviceShadow* sh, float3 q) {
  return sh->kind == MP_SHADOW_SUN ? fmax(sh->z_top - q.z, 0.0f) : MP_SHADOW_SEARCH_SCALE;
}

/* One round of the search at kernel scale s: the first (0), the look
 * straight at the light (2) or the second (1). The occluders found
 * (*found, their ratios' *sum and the *nearest ratio); returns the level it
 * read, or the level count when no level had its pages. */
MP_INLINE int mp_blocker_round(const MpShadowMaps* in, const MP_GLOBAL DeviceShadow* sh, const MpLightShape* shape,
                               float3 q, float3 n, float bias, int base, int round, float s, uint* plane_key,
                               MpReceiverPlane* plane, float* found, float* sum, float* nearest) {
  int count = mp_shadow_level_count(sh), sun = sh->kind == MP_SHADOW_SUN;
  int ls = mp_shadow_level_for_size(sh, q, mp_light_shape_radius(sh) * s, MP_SHADOW_SEARCH_TEXELS, base);
  for (; ls < count; ++ls) {
    int missing = 0;
    *found = *sum = 0.0f;
    *nearest = 3.0e38f;
    float2 turn = MP_F2(1.0f, 0.0f);
    const int taps = round == 1 ? MP_SHADOW_TAPS : round ? 1 : MP_SHADOW_PROBE_TAPS;
    MpShadowMap m;
    for (int k = 0; k < taps && !missing; ++k, turn = mp_golden_step(turn)) {
      float reach;
      float3 o = mp_search_tap(shape, k, taps, turn, &reach);
      float3 x = mp_kernel_point(q, o, s);
      mp_shadow_map_for(in, sh, x, ls, k == 0, &m);
      float3 r = mp_shadow_project(&m, x);
      mp_plane_for(&m, q, n, r.z, plane_key, plane);
      float b = bias * mp_shadow_texel_size(&m, r.z) + MP_SHADOW_SOFT_BIAS * length(o) * s;
      float ratio;
      if (mp_shadow_blocker(in, &m, plane, r.x, r.y, r.z, b, sun, round ? s * reach : 0.0f, &ratio, &missing)) {
        *found += 1.0f;
        *sum += ratio;
        *nearest = fmin(*nearest, ratio);
      }
    }
    if (!missing) return ls;
  }
  return count;
}

/* The (fractional) level at which a filter kernel of radius `size` (scene
 * units at q) spans MP_SHADOW_FILTER_TEXELS texels. */
MP_INLINE float mp_filter_level(const MP_GLOBAL DeviceShadow* sh, float3 q, float size) {
  size = fmax(size / MP_SHADOW_FILTER_TEXELS, 1e-30f);
  if (sh->kind == MP_SHADOW_SUN) return log2(size) - (float)sh->level0;
  float3 a = MP_F3(fabs(q.x), fabs(q.y), fabs(q.z));
  return log2(fmax(size * (float)(MP_MAP_TEXELS / 2) / fmax(fmax(a.x, fmax(a.y, a.z)), 1e-30f), 1e-30f));
}

/* Visibility of the light from a receiver at light-space q with geometric
 * normal n, footprint in scene units: 1 lit, 0 in shadow. */
MP_INLINE float mp_shadow_visibility_light(const MpShadowMaps* in, const MP_GLOBAL DeviceShadow* sh, float3 q, float3 n,
                                           float footprint) {
  int count = mp_shadow_level_count(sh);
  int base = mp_shadow_base_level(sh, q, footprint);
  float bias = mp_shadow_bias_texels(sh, q, n);
  float radius = mp_light_shape_radius(sh);
  if (sh->shape == MP_SHADOW_SHAPE_POINT || !(radius > 0.0f)) {
    for (int l = base; l < count; ++l) {
      MpShadowMap m = mp_shadow_map_at(in, sh, q, l);
      float3 r = mp_shadow_project(&m, q);
      MpReceiverPlane plane = mp_receiver_plane(&m, q, n, r.z);
      int missing = 0;
      float lit = mp_shadow_bilinear(in, &m, &plane, r.x, r.y, r.z, bias * mp_shadow_texel_size(&m, r.z), &missing);
      if (!missing) return lit;
    }
    return 1.0f;
  }
  MpLightShape shape = mp_light_shape(sh, q);
  uint plane_key = 0xffffffffu;
  MpReceiverPlane plane;
  float2 shift;
  const float2 spin = mp_filter_spin(q, &shift);
  const float widest = mp_first_search_scale(sh, q);
  float found, sum, nearest;
  int ls = mp_blocker_round(in, sh, &shape, q, n, bias, base, 0, widest, &plane_key, &plane, &found, &sum, &nearest);
  if (ls >= count) return 1.0f;
  if (!(found > 0.0f)) {
    /* None in the wide round's texels: straight at the light, at the receiver's level. */
    if (ls == base || mp_blocker_round(in, sh, &shape, q, n, bias, base, 2, 0.0f, &plane_key, &plane, &found, &sum,
                                       &nearest) >= count)
      return 1.0f;
    if (!(found > 0.0f)) return 1.0f;
  }
  float first = sum / found;
  float search_scale = fmin(widest, 2.0f * first);
  mp_blocker_round(in, sh, &shape, q, n, bias, base, 1, search_scale, &plane_key, &plane, &found, &sum,
                   &nearest);
  if (found >= (float)MP_SHADOW_TAPS - 1e-3f) return 0.0f;
  /* Where the denser search finds none (the outer penumbra, where occluders
   * hide a sliver of the light), the first estimate stands. */
  float scale = found > 0.0f ? sum / found : first;
  /* The penumbra kernel: the light's shape scaled by the mean occluder's
   * distance, filtered where it spans a few texels. Its taps are spread
   * between the two levels around that size in proportion to where it lies
   * between them, so that the filter does not jump from one level to the
   * next across a penumbra. */
  float level = clamp(mp_filter_level(sh, q, radius * scale), (float)base, (float)(count - 1));
  int l0 = (int)floor(level);
  float blend = level - (float)l0;
  float lit = 0.0f;
  float2 turn = spin;
  MpShadowMap m[2];
  int levels[2] = {-1, -1};
  uint keys[2] = {0xffffffffu, 0xffffffffu};
  MpReceiverPlane planes[2];
  for (int i = 0; i < MP_SHADOW_TAPS; ++i) {
    if (i == MP_SHADOW_TAPS / 2) {
      /* Half the taps seen: where all see the light (lit beside the
       * occluders), the other half do too. (Stopping where all eight are in
       * shadow left dark streaks in penumbrae, where thin gaps let the
       * light through between the first half's taps; umbrae end in the
       * blocker search instead.) */
      if (lit == (float)i) return 1.0f;
      turn = mp_golden_step(spin);
    }
    float3 o = mp_filter_tap(&shape, i, turn, shift);
    turn = mp_golden_step2(turn);
    float3 x = mp_kernel_point(q, o, scale);
    int which = mp_tap_dither(i) < blend;
    float b0 = MP_SHADOW_SOFT_BIAS * length(o) * scale;
    for (int lp = l0 + which; lp < count; ++lp) {
      int slot = lp == l0 ? 0 : 1, missing = 0;
      mp_shadow_map_for(in, sh, x, lp, levels[slot] != lp, &m[slot]);
      levels[slot] = lp;
      float3 r = mp_shadow_project(&m[slot], x);
      mp_plane_for(&m[slot], q, n, r.z, &keys[slot], &planes[slot]);
      float t = mp_shadow_bilinear(in, &m[slot], &planes[slot], r.x, r.y, r.z,
                                   bias * mp_shadow_texel_size(&m[slot], r.z) + b0, &missing);
      if (!missing) {
        lit += t;
        break;
      }
      if (lp + 1 == count) lit += 1.0f;
    }
  }
  return lit / (float)MP_SHADOW_TAPS;
}

/* Visibility of light `light` at camera-space point p with geometric normal n. */
MP_INLINE float mp_shadow_visibility(const MpShadowMaps* in, uint light, float3 p, float3 n, float footprint) {
  const MP_GLOBAL DeviceShadow* sh = in->shadows + light;
  if (sh->kind == MP_SHADOW_NONE) return 1.0f;
  return mp_shadow_visibility_light(in, sh, mp_xform_point(sh->to_light, p), mp_xform_dir(sh->to_light, n), footprint);
}

#endif
