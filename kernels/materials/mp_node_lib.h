/* Blender shader nodes as device functions: what material programs (node
 * trees translated to OpenCL C by the add-on, see material_program.cl) call.
 * Each function reproduces the node's documented behaviour in Blender,
 * including its guards (division by zero gives 0, and so on), so a node tree
 * computes the same values here as in Cycles. Operation codes are the
 * MP_MATH_*, MP_VMATH_*, MP_BLEND_* and MP_RANGE_* constants below; the
 * add-on's node compiler maps Blender's enum names onto them. */
#ifndef MP_NODE_LIB_H
#define MP_NODE_LIB_H

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "closures/mp_closures.h"
#include "closures/mp_principled.h"
#include "closures/mp_hair.h"
#include "textures/mp_vector_rotate.h"

/* What the nodes can read at a shading point. Object-space position and
 * normal (Texture Coordinate > Object and Normal), Generated coordinates,
 * the scene's UV layers (z = 0, as Blender's UV output) and the texture
 * images (Image Texture, textures/mp_tex_image.h).
 *
 * Normals and tangents that pass between nodes are in world space, as in
 * Cycles (Geometry > Normal, Bump, Normal Map, a BSDF's Normal input); the
 * node compiler turns a BSDF's into object space where it enters the
 * closures (MpSurface's normals, which shade_program_grids maps to camera
 * space). */
/* How many UV layers a program reads: the node compiler says
 * ("#define MP_NODE_USES_UV_LAYERS n", the layers the scene's materials had
 * taken when it compiled this one), so a program keeps only those in its
 * globals; every layer where it does not say. */
#ifndef MP_NODE_USES_UV_LAYERS
#define MP_NODE_USES_UV_LAYERS MP_MAX_UV_LAYERS
#endif

typedef struct MpNodeGlobals {
  float3 P;
  float3 N;  /* unit normal, object space */
  float3 Nw; /* the same in world space (Cycles' N) */
  float3 generated;
  float3 I; /* unit direction towards the viewer, world space (Geometry > Incoming) */
  float3 camera; /* the point in Cycles' camera space, +Z forward (Texture Coordinate > Camera) */
  float3 window; /* the image's normalised device coordinates, z = 0 (Texture Coordinate > Window) */
  float ray_length; /* distance from the camera (Light Path > Ray Length) */
  int shadow_ray;   /* evaluated for a shadow map's transparency (Light Path > Is Shadow Ray) */
  int camera_ray;   /* shading what the camera sees (Light Path > Is Camera Ray): not for shadow
                       maps, displacement or the world's light, as in Cycles */
  int backfacing;   /* the surface faces away from the viewer (Geometry > Backfacing) */
  float3 fibre;     /* unit direction of the patch's v (a hair tube's root to tip), object space;
                       computed only for programs with hair closures (MP_NODE_USES_HAIR), else zero */
  float fibre_radius; /* a hair tube's radius (camera space; 0 where unknown), likewise */
  float3 uv[MP_NODE_USES_UV_LAYERS]; /* the layers the program reads (see below) */
  MP_GLOBAL const DeviceObject* object; /* object <-> world (world-space nodes), or null */
  /* The object's values of the Attribute nodes of type Object or Instancer
   * (the slots the add-on numbers, export_attributes.py), or null. */
  MP_GLOBAL const float4* attributes;
  uint attribute_count;
  MP_GLOBAL const DeviceImage* images;
  MP_GLOBAL const float4* texels;
  uint image_count;
  /* The material's node values (its parameters, node_compiler.py): the
   * numbers a program reads rather than compiles in, so that a tree whose
   * values change keeps its program and only these are uploaded again. */
  MP_GLOBAL const float* params;
  /* The same MP_NEIGHBOUR_STEP of the way to the next grid vertex along u
   * and along v (the finite differences of Bump nodes and the footprints
   * of image lookups), or null. */
  const struct MpNodeGlobals* dx;
  const struct MpNodeGlobals* dy;
  float footprint; /* image lookups' filter width in micropolygons (FrameParams.texture_filter) */
} MpNodeGlobals;

/* The fraction of a micropolygon that globals' dx and dy step. */
#define MP_NEIGHBOUR_STEP 0.1f

/* The change of a node value v (computed as `at_dx` at g->dx) over one whole
 * micropolygon, times the filter width: an image lookup's footprint; zero
 * without neighbours. */
#define MP_FOOTPRINT(g, at_dx, v) ((g)->dx ? ((at_dx) - (v)) * ((g)->footprint / MP_NEIGHBOUR_STEP) : (v) * 0.0f)

/* The change of a node value v (computed as `at_dx` at g->dx) over one whole
 * micropolygon; zero without neighbours. */
#define MP_STEP_CHANGE(g, at_dx, v) ((g)->dx ? ((at_dx) - (v)) * (1.0f / MP_NEIGHBOUR_STEP) : 0.0f)

/* A hard alpha cut (a Math Greater Than into Alpha: opaque where s > 0) as
 * the side of its edge written with the edge's distance: 0.5 + s over
 * twice the most s changes across a micropolygon (dx, dy: its change along
 * each grid axis), clamped to [0, 1]. Within a micropolygon the edge
 * crosses, the corners' values stay unclamped, so the opacity interpolated
 * across it passes one half where s passes zero; the sampler keeps such
 * surfaces where that opacity exceeds one half (materials whose alpha is
 * a cut, DeviceMaterial.program[3] = 2), so the edge falls where the cut
 * falls, not halfway between two corners. */
MP_INLINE float mp_alpha_cut(float s, float dx, float dy) {
  float w = 1.41421356f * sqrt(dx * dx + dy * dy);
  if (!(w > 0.0f) || !isfinite(w)) return s > 0.0f ? 1.0f : 0.0f;
  return clamp(0.5f + s / (2.0f * w), 0.0f, 1.0f);
}

/* Node value k of the material, and three (four) from k as a vector or
 * colour; a table of n from k. Programs name them only in these forms, with
 * k and n literals, so the host can tell how many values a program reads
 * (validate_scene.cpp). */
MP_INLINE float3 mp_param3(const MpNodeGlobals* g, int k) {
  return MP_F3(g->params[k], g->params[k + 1], g->params[k + 2]);
}
MP_INLINE float4 mp_param4(const MpNodeGlobals* g, int k) {
  return (float4)(g->params[k], g->params[k + 1], g->params[k + 2], g->params[k + 3]);
}
#define MP_PARAM(k) (g->params[k])
#define MP_PARAM3(k) mp_param3(g, k)
#define MP_PARAM4(k) mp_param4(g, k)
#define MP_PARAM_TABLE(k, n) (g->params + (k)) /* n values from k: a curve's samples */


/* World-space vectors for nodes that work in world space: a direction from
 * world to object space, and an object-space normal to world space and back
 * (normals map by the inverse transpose). Without an object, unchanged. */
MP_INLINE float3 mp_nl_rows(const MP_GLOBAL float* m, float3 v) {
  return MP_F3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
               m[8] * v.x + m[9] * v.y + m[10] * v.z);
}
MP_INLINE float3 mp_nl_columns(const MP_GLOBAL float* m, float3 v) {
  return MP_F3(m[0] * v.x + m[4] * v.y + m[8] * v.z, m[1] * v.x + m[5] * v.y + m[9] * v.z,
               m[2] * v.x + m[6] * v.y + m[10] * v.z);
}
MP_INLINE float3 mp_nl_safe_normalize(float3 a) {
  float l = length(a);
  return l > 0.0f ? a / l : MP_F3(0.0f, 0.0f, 0.0f);
}
MP_INLINE float3 mp_world_dir_to_object(const MpNodeGlobals* g, float3 v) {
  return g->object ? mp_nl_rows(g->object->from_world, v) : v;
}
MP_INLINE float3 mp_object_normal_to_world(const MpNodeGlobals* g, float3 n) {
  if (!g->object) return n;
  float3 w = mp_nl_columns(g->object->from_world, n);
  float len = length(w);
  return len > 0.0f ? w / len : n;
}
MP_INLINE float3 mp_world_normal_to_object(const MpNodeGlobals* g, float3 n) {
  if (!g->object) return n;
  float3 o = mp_nl_columns(g->object->to_world, n);
  float len = length(o);
  return len > 0.0f ? o / len : n;
}

/* The tangent a BSDF without a Tangent input uses: the Tangent node's
 * default, radial about the object's Z axis through Generated coordinates
 * (object space, unnormalised). */
MP_INLINE float3 mp_radial_tangent(const MpNodeGlobals* g) {
  return MP_F3(-(g->generated.y - 0.5f), g->generated.x - 0.5f, 0.0f);
}

/* Radial about the object's X (axis 0), Y (1) or Z (2) axis, as the Tangent
 * node's Radial directions (object space, unnormalised). */
MP_INLINE float3 mp_radial_tangent_axis(const MpNodeGlobals* g, int axis) {
  float3 c = g->generated - MP_F3(0.5f, 0.5f, 0.5f);
  if (axis == 0) return MP_F3(0.0f, -c.z, c.y);
  if (axis == 1) return MP_F3(-c.z, 0.0f, c.x);
  return MP_F3(-c.y, c.x, 0.0f);
}

/* A UV map's MikkTSpace tangent, object space, from the layers holding it
 * (ta: its x and y; tb: its z and the bitangent sign, into *sign when
 * given), or zero where they are -1. */
MP_INLINE float3 mp_uv_tangent(const MpNodeGlobals* g, int ta, int tb, float* sign) {
  if (ta < 0 || tb < 0) return MP_F3(0.0f, 0.0f, 0.0f);
  if (sign) *sign = g->uv[tb].y < 0.0f ? -1.0f : 1.0f;
  return MP_F3(g->uv[ta].x, g->uv[ta].y, g->uv[tb].x);
}

/* A tangent node output from an object-space direction t, as Cycles makes
 * it (svm tangent, primitive_tangent): turned into world space as a normal
 * is, then made orthogonal to the normal. Zero where t is. */
MP_INLINE float3 mp_world_tangent(const MpNodeGlobals* g, float3 t) {
  float3 w = mp_object_normal_to_world(g, t);
  return cross(g->Nw, mp_nl_safe_normalize(cross(w, g->Nw)));
}

/* Hair Info's Tangent Normal: the direction to the viewer with its part
 * along the fibre removed (Cycles' curve_tangent_normal), in world space;
 * zero off hair (g->fibre unset). */
MP_INLINE float3 mp_hair_tangent_normal(const MpNodeGlobals* g) {
  float3 t = g->object ? mp_nl_rows(g->object->to_world, g->fibre) : g->fibre;
  float tt = dot(t, t);
  if (!(tt > 0.0f)) return MP_F3(0.0f, 0.0f, 0.0f);
  return mp_nl_safe_normalize(g->I - t * (dot(t, g->I) / tt));
}

/* The cosine between the view and object-space normal n (the Principled
 * BSDF's layering, whose normals are the closures'), taken in world space. */
MP_INLINE float mp_view_cos(const MpNodeGlobals* g, float3 n) { return dot(mp_object_normal_to_world(g, n), g->I); }

/* Whether the surface faces away from the viewer (Geometry > Backfacing). */
MP_INLINE int mp_backfacing(const MpNodeGlobals* g) { return g->backfacing; }

/* Fresnel node: the dielectric reflectance of IOR ior (its inverse seen
 * from behind) at the view's angle to world-space normal n. */
MP_INLINE float mp_fresnel_node(const MpNodeGlobals* g, float ior, float3 n) {
  float eta = fmax(ior, 1e-5f);
  if (mp_backfacing(g)) eta = 1.0f / eta;
  return mp_fresnel_dielectric(dot(n, g->I), eta);
}

/* Layer Weight node: Fresnel (of IOR 1 / (1 - blend)) and Facing
 * (1 - |cos|^p, p = 2 blend below a half, 0.5 / (1 - blend) above), for
 * world-space normal n. */
MP_INLINE float mp_layer_weight(const MpNodeGlobals* g, float blend, float3 n, float* facing) {
  float c = dot(n, g->I);
  float eta = fmax(1.0f - blend, 1e-5f);
  float fresnel = mp_fresnel_dielectric(c, mp_backfacing(g) ? eta : 1.0f / eta);
  float f = fabs(c);
  if (blend != 0.5f) {
    float b = clamp(blend, 0.0f, 1.0f - 1e-5f);
    f = MP_POWR(f, b < 0.5f ? 2.0f * b : 0.5f / (1.0f - b));
  }
  *facing = 1.0f - f;
  return fresnel;
}

/* Attribute node of type Object or Instancer: this object's value in
 * `slot`; zero where it has none (Cycles' value for a name it finds
 * nowhere). */
MP_INLINE float4 mp_object_attribute(const MpNodeGlobals* g, uint slot) {
  return g->attributes && slot < g->attribute_count ? g->attributes[slot] : (float4)(0.0f);
}

/* This point in world space (Geometry > Position). */
MP_INLINE float3 mp_world_position(const MpNodeGlobals* g) {
  if (!g->object) return g->P;
  const MP_GLOBAL float* m = g->object->to_world;
  return mp_nl_rows(m, g->P) + MP_F3(m[3], m[7], m[11]);
}

/* ---- Vector Transform: between world, object and camera space ----------
 * As Cycles converts (svm vector_transform): points with the translation,
 * vectors without, normals by the inverse transpose and normalised whenever
 * the space changes. Camera space is Cycles' (+Z forward: Blender's camera
 * space with Z mirrored); object space is the hub every conversion passes.
 * Without an object (a RIB shape without one), unchanged. */
#define MP_VT_POINT 0
#define MP_VT_VECTOR 1
#define MP_VT_NORMAL 2
#define MP_SPACE_WORLD 0
#define MP_SPACE_OBJECT 1
#define MP_SPACE_CAMERA 2

/* Points and vectors by a 3x4's rows; normals by the columns of the
 * inverse (`inverse`), which is the inverse transpose. */
MP_INLINE float3 mp_nl_convert(const MP_GLOBAL float* m, const MP_GLOBAL float* inverse, int type, float3 v) {
  if (type == MP_VT_NORMAL) return mp_nl_columns(inverse, v);
  float3 r = mp_nl_rows(m, v);
  return type == MP_VT_POINT ? r + MP_F3(m[3], m[7], m[11]) : r;
}

/* Before 4.0 Cycles turned normals as vectors and normalised them always,
 * even within one space (`v3_normals`). */
MP_INLINE float3 mp_vector_transform(const MpNodeGlobals* g, int type, int from, int to, float3 v, int v3_normals) {
  int normal = type == MP_VT_NORMAL, as = normal && v3_normals ? MP_VT_VECTOR : type;
  if (from == to || !g->object) return normal && v3_normals ? mp_nl_safe_normalize(v) : v;
  MP_GLOBAL const DeviceObject* o = g->object;
  if (from == MP_SPACE_WORLD) v = mp_nl_convert(o->from_world, o->to_world, as, v);
  if (from == MP_SPACE_CAMERA) v = mp_nl_convert(o->to_object, o->to_camera, as, MP_F3(v.x, v.y, -v.z));
  if (to == MP_SPACE_WORLD) v = mp_nl_convert(o->to_world, o->from_world, as, v);
  if (to == MP_SPACE_CAMERA) {
    v = mp_nl_convert(o->to_camera, o->to_object, as, v);
    v.z = -v.z;
  }
  return normal ? mp_nl_safe_normalize(v) : v;
}

/* This shading point in another object's space (Texture Coordinate ▸ Object
 * with an object set): world -> that object given as the rows of a 3x4. */
MP_INLINE float3 mp_point_in_space(const MpNodeGlobals* g, float4 r0, float4 r1, float4 r2) {
  float3 w = mp_world_position(g);
  return MP_F3(r0.x * w.x + r0.y * w.y + r0.z * w.z + r0.w, r1.x * w.x + r1.y * w.y + r1.z * w.z + r1.w,
               r2.x * w.x + r2.y * w.y + r2.z * w.z + r2.w);
}

/* Displacement node in World space: height along the world-space normal,
 * in world units (Cycles), as an object-space vector. */
MP_INLINE float3 mp_displacement_world(const MpNodeGlobals* g, float amount) {
  return mp_world_dir_to_object(g, g->Nw * amount);
}

/* Vector Displacement in tangent space, as Cycles reads it: x along the
 * UV map's tangent (layers ta and tb as for mp_normal_map_tangent; -1:
 * none, only y displaces), y along the normal, z along the bitangent (the
 * normal x tangent, by the tangent's sign); object space. */
MP_INLINE float3 mp_vector_displacement_tangent(const MpNodeGlobals* g, int ta, int tb, float3 d) {
  float sign = 1.0f;
  float3 n = g->N, t = mp_uv_tangent(g, ta, tb, &sign);
  float3 b = sign * mp_nl_safe_normalize(cross(n, t));
  return t * d.x + n * d.y + b * d.z;
}

/* Bump node: the normal tilted by the height's gradient over the surface,
 * from heights at the point and a small step along u and v (hc, hx, hy),
 * with the surface-gradient formulation Cycles' Bump node uses: tangents
 * Rx = dPdy x N and Ry = N x dPdx, and the normal |det| N - distance
 * sign(det) ((hx - hc) Rx + (hy - hc) Ry), blended with N by strength.
 * World space, as Cycles: distance is in world units. */
MP_INLINE float3 mp_bump(const MpNodeGlobals* g, float hc, float hx, float hy, float strength, float distance,
                         int invert, float3 n_in) {
  if (g->dx == 0 || g->dy == 0) return n_in;
  float3 pw = mp_world_position(g);
  float3 dpdx = mp_world_position(g->dx) - pw, dpdy = mp_world_position(g->dy) - pw;
  float3 rx = cross(dpdy, n_in), ry = cross(n_in, dpdx);
  float det = dot(dpdx, rx);
  float3 surfgrad = (hx - hc) * rx + (hy - hc) * ry;
  if (invert) distance = -distance;
  float3 n = fabs(det) * n_in - distance * (det < 0.0f ? -1.0f : 1.0f) * surfgrad;
  float len = length(n);
  if (!(len > 0.0f) || !isfinite(len)) return n_in;
  n = n / len;
  strength = fmax(strength, 0.0f);
  n = strength * n + (1.0f - strength) * n_in;
  len = length(n);
  return len > 0.0f ? n / len : n_in;
}

/* Normal Map node, as Cycles evaluates it: the color is mapped to [-1, 1],
 * then read in tangent space (below), object or world space, and the
 * result (world space) is blended with the surface normal by strength. */
MP_INLINE float3 mp_normal_map_strength(const MpNodeGlobals* g, float3 n, float strength) {
  if (strength != 1.0f) n = g->Nw + (n - g->Nw) * fmax(strength, 0.0f);
  float len = length(n);
  return len > 0.0f && isfinite(len) ? n / len : g->Nw;
}

/* Tangent space, for the UV map in layer `uv`. Layers `ta` and `tb` hold
 * its tangents (tangent xy, then tangent z and the bitangent sign: MikkTSpace
 * tangents per face corner, as Blender computes them and Cycles interpolates
 * them), or are -1. Where there are none, or they are zero (a mesh Blender
 * computes no tangents for), the tangent is the direction of increasing U
 * on the surface, from the UV differences to the grid neighbours, made
 * orthogonal to the normal. `v4`: Blender 4.0's Strength (below). */
MP_INLINE float3 mp_normal_map_tangent(const MpNodeGlobals* g, int uv, int ta, int tb, float strength,
                                       float3 color, int v4) {
  /* The tangent frame is the object's: its tangents and UV differences are
   * object-space. */
  float sign = 1.0f;
  float3 n = g->N, t = mp_uv_tangent(g, ta, tb, &sign);
  if (!(dot(t, t) > 0.0f)) {
    if (g->dx == 0 || g->dy == 0) return g->Nw;
    float3 p1 = g->dx->P - g->P, p2 = g->dy->P - g->P;
    float3 uv1 = g->dx->uv[uv] - g->uv[uv], uv2 = g->dy->uv[uv] - g->uv[uv];
    float det = uv1.x * uv2.y - uv2.x * uv1.y;
    if (!(fabs(det) > 0.0f)) return g->Nw;
    float3 du = (p1 * uv2.y - p2 * uv1.y) / det; /* dP/dU */
    float3 dv = (p2 * uv1.x - p1 * uv2.x) / det; /* dP/dV */
    t = du - n * dot(n, du);
    if (!(dot(t, t) > 0.0f)) return g->Nw;
    t = normalize(t);
    sign = dot(cross(n, t), dv) < 0.0f ? -1.0f : 1.0f;
  }
  float3 c = 2.0f * (color - MP_F3(0.5f, 0.5f, 0.5f));
  if (v4) {
    /* Blender 4.0: strength scales the tilt, never pushing the normal below
     * the surface; no blend afterwards. */
    c.x *= strength, c.y *= strength;
    c.z = 1.0f + (c.z - 1.0f) * fmin(fmax(strength, 0.0f), 1.0f);
    strength = 1.0f;
  }
  float3 b = sign * cross(n, t);
  return mp_normal_map_strength(g, mp_object_normal_to_world(g, c.x * t + c.y * b + c.z * n), strength);
}

/* Object or world space; Blender's own spaces have y and z flipped. */
MP_INLINE float3 mp_normal_map_object(const MpNodeGlobals* g, int blender_space, int world, float strength,
                                      float3 color) {
  float3 c = 2.0f * (color - MP_F3(0.5f, 0.5f, 0.5f));
  if (blender_space) c.y = -c.y, c.z = -c.z;
  float len = length(c);
  if (!(len > 0.0f)) return g->Nw;
  c = c / len;
  return mp_normal_map_strength(g, world ? c : mp_object_normal_to_world(g, c), strength);
}

MP_INLINE float mp_nl_safe_div(float a, float b) { return b != 0.0f ? a / b : 0.0f; }
MP_INLINE float mp_nl_fract(float a) { return a - floor(a); }
MP_INLINE float mp_nl_clamp01(float a) { return fmin(fmax(a, 0.0f), 1.0f); }
MP_INLINE float mp_nl_wrap(float a, float hi, float lo) {
  float range = hi - lo;
  return range != 0.0f ? a - range * floor((a - lo) / range) : lo;
}
MP_INLINE float mp_nl_pingpong(float a, float scale) {
  return scale != 0.0f ? fabs(mp_nl_fract((a - scale) / (scale * 2.0f)) * scale * 2.0f - scale) : 0.0f;
}
MP_INLINE float mp_nl_smoothmin(float a, float b, float k) {
  if (!(k != 0.0f)) return fmin(a, b);
  float h = fmax(k - fabs(a - b), 0.0f) / k;
  return fmin(a, b) - h * h * h * k * (1.0f / 6.0f);
}
MP_INLINE float mp_nl_safe_fmod(float a, float b) { return b != 0.0f ? a - b * trunc(a / b) : 0.0f; }

/* ---- Math node ---------------------------------------------------------- */
#define MP_MATH_ADD 0
#define MP_MATH_SUBTRACT 1
#define MP_MATH_MULTIPLY 2
#define MP_MATH_DIVIDE 3
#define MP_MATH_MULTIPLY_ADD 4
#define MP_MATH_POWER 5
#define MP_MATH_LOGARITHM 6
#define MP_MATH_SQRT 7
#define MP_MATH_INVERSE_SQRT 8
#define MP_MATH_ABSOLUTE 9
#define MP_MATH_EXPONENT 10
#define MP_MATH_MINIMUM 11
#define MP_MATH_MAXIMUM 12
#define MP_MATH_LESS_THAN 13
#define MP_MATH_GREATER_THAN 14
#define MP_MATH_SIGN 15
#define MP_MATH_COMPARE 16
#define MP_MATH_SMOOTH_MIN 17
#define MP_MATH_SMOOTH_MAX 18
#define MP_MATH_ROUND 19
#define MP_MATH_FLOOR 20
#define MP_MATH_CEIL 21
#define MP_MATH_TRUNC 22
#define MP_MATH_FRACT 23
#define MP_MATH_MODULO 24
#define MP_MATH_FLOORED_MODULO 25
#define MP_MATH_WRAP 26
#define MP_MATH_SNAP 27
#define MP_MATH_PINGPONG 28
#define MP_MATH_SINE 29
#define MP_MATH_COSINE 30
#define MP_MATH_TANGENT 31
#define MP_MATH_ARCSINE 32
#define MP_MATH_ARCCOSINE 33
#define MP_MATH_ARCTANGENT 34
#define MP_MATH_ARCTAN2 35
#define MP_MATH_SINH 36
#define MP_MATH_COSH 37
#define MP_MATH_TANH 38
#define MP_MATH_RADIANS 39
#define MP_MATH_DEGREES 40

MP_INLINE float mp_math(int op, float a, float b, float c) {
  switch (op) {
    case MP_MATH_ADD: return a + b;
    case MP_MATH_SUBTRACT: return a - b;
    case MP_MATH_MULTIPLY: return a * b;
    case MP_MATH_DIVIDE: return mp_nl_safe_div(a, b);
    case MP_MATH_MULTIPLY_ADD: return a * b + c;
    case MP_MATH_POWER:
      if (a >= 0.0f) return pow(a, b);
      /* A negative base only for integer exponents, as Blender's safe power. */
      return b == floor(b) ? (fmod(fabs(b), 2.0f) == 1.0f ? -pow(-a, b) : pow(-a, b)) : 0.0f;
    case MP_MATH_LOGARITHM: return (a > 0.0f && b > 0.0f) ? log(a) / log(b) : 0.0f;
    case MP_MATH_SQRT: return a > 0.0f ? sqrt(a) : 0.0f;
    case MP_MATH_INVERSE_SQRT: return a > 0.0f ? 1.0f / sqrt(a) : 0.0f;
    case MP_MATH_ABSOLUTE: return fabs(a);
    case MP_MATH_EXPONENT: return exp(a);
    case MP_MATH_MINIMUM: return fmin(a, b);
    case MP_MATH_MAXIMUM: return fmax(a, b);
    case MP_MATH_LESS_THAN: return a < b ? 1.0f : 0.0f;
    case MP_MATH_GREATER_THAN: return a > b ? 1.0f : 0.0f;
    case MP_MATH_SIGN: return a > 0.0f ? 1.0f : a < 0.0f ? -1.0f : 0.0f;
    case MP_MATH_COMPARE: return fabs(a - b) <= fmax(c, 1e-5f) ? 1.0f : 0.0f;
    case MP_MATH_SMOOTH_MIN: return mp_nl_smoothmin(a, b, c);
    case MP_MATH_SMOOTH_MAX: return -mp_nl_smoothmin(-a, -b, c);
    case MP_MATH_ROUND: return floor(a + 0.5f);
    case MP_MATH_FLOOR: return floor(a);
    case MP_MATH_CEIL: return ceil(a);
    case MP_MATH_TRUNC: return trunc(a);
    case MP_MATH_FRACT: return mp_nl_fract(a);
    case MP_MATH_MODULO: return mp_nl_safe_fmod(a, b);
    case MP_MATH_FLOORED_MODULO: return b != 0.0f ? a - floor(a / b) * b : 0.0f;
    case MP_MATH_WRAP: return mp_nl_wrap(a, b, c);
    case MP_MATH_SNAP: return b != 0.0f ? floor(a / b) * b : 0.0f;
    case MP_MATH_PINGPONG: return mp_nl_pingpong(a, b);
    case MP_MATH_SINE: return sin(a);
    case MP_MATH_COSINE: return cos(a);
    case MP_MATH_TANGENT: return tan(a);
    case MP_MATH_ARCSINE: return asin(fmin(fmax(a, -1.0f), 1.0f));
    case MP_MATH_ARCCOSINE: return acos(fmin(fmax(a, -1.0f), 1.0f));
    case MP_MATH_ARCTANGENT: return atan(a);
    case MP_MATH_ARCTAN2: return atan2(a, b);
    case MP_MATH_SINH: return sinh(a);
    case MP_MATH_COSH: return cosh(a);
    case MP_MATH_TANH: return tanh(a);
    case MP_MATH_RADIANS: return a * (3.14159265358979f / 180.0f);
    case MP_MATH_DEGREES: return a * (180.0f / 3.14159265358979f);
  }
  return 0.0f;
}

/* ---- Vector Math node --------------------------------------------------- */
#define MP_VMATH_ADD 0
#define MP_VMATH_SUBTRACT 1
#define MP_VMATH_MULTIPLY 2
#define MP_VMATH_DIVIDE 3
#define MP_VMATH_MULTIPLY_ADD 4
#define MP_VMATH_CROSS_PRODUCT 5
#define MP_VMATH_PROJECT 6
#define MP_VMATH_REFLECT 7
#define MP_VMATH_DOT_PRODUCT 8
#define MP_VMATH_DISTANCE 9
#define MP_VMATH_LENGTH 10
#define MP_VMATH_SCALE 11
#define MP_VMATH_NORMALIZE 12
#define MP_VMATH_ABSOLUTE 13
#define MP_VMATH_MINIMUM 14
#define MP_VMATH_MAXIMUM 15
#define MP_VMATH_FLOOR 16
#define MP_VMATH_CEIL 17
#define MP_VMATH_FRACTION 18
#define MP_VMATH_MODULO 19
#define MP_VMATH_WRAP 20
#define MP_VMATH_SNAP 21
#define MP_VMATH_SINE 22
#define MP_VMATH_COSINE 23
#define MP_VMATH_TANGENT 24
#define MP_VMATH_FACEFORWARD 25


/* Returns the vector output; *value gets the float output. */
MP_INLINE float3 mp_vector_math(int op, float3 a, float3 b, float3 c, float scale, float* value) {
  *value = 0.0f;
  switch (op) {
    case MP_VMATH_ADD: return a + b;
    case MP_VMATH_SUBTRACT: return a - b;
    case MP_VMATH_MULTIPLY: return a * b;
    case MP_VMATH_DIVIDE: return MP_F3(mp_nl_safe_div(a.x, b.x), mp_nl_safe_div(a.y, b.y), mp_nl_safe_div(a.z, b.z));
    case MP_VMATH_MULTIPLY_ADD: return a * b + c;
    case MP_VMATH_CROSS_PRODUCT: return cross(a, b);
    case MP_VMATH_PROJECT: {
      float bb = dot(b, b);
      return bb != 0.0f ? b * (dot(a, b) / bb) : MP_F3(0.0f, 0.0f, 0.0f);
    }
    case MP_VMATH_REFLECT: {
      float3 n = mp_nl_safe_normalize(b);
      return a - 2.0f * dot(n, a) * n;
    }
    case MP_VMATH_FACEFORWARD: return dot(c, b) < 0.0f ? a : -a;
    case MP_VMATH_DOT_PRODUCT: *value = dot(a, b); return MP_F3(0.0f, 0.0f, 0.0f);
    case MP_VMATH_DISTANCE: *value = length(a - b); return MP_F3(0.0f, 0.0f, 0.0f);
    case MP_VMATH_LENGTH: *value = length(a); return MP_F3(0.0f, 0.0f, 0.0f);
    case MP_VMATH_SCALE: return a * scale;
    case MP_VMATH_NORMALIZE: return mp_nl_safe_normalize(a);
    case MP_VMATH_ABSOLUTE: return MP_F3(fabs(a.x), fabs(a.y), fabs(a.z));
    case MP_VMATH_MINIMUM: return fmin(a, b);
    case MP_VMATH_MAXIMUM: return fmax(a, b);
    case MP_VMATH_FLOOR: return MP_F3(floor(a.x), floor(a.y), floor(a.z));
    case MP_VMATH_CEIL: return MP_F3(ceil(a.x), ceil(a.y), ceil(a.z));
    case MP_VMATH_FRACTION: return MP_F3(mp_nl_fract(a.x), mp_nl_fract(a.y), mp_nl_fract(a.z));
    case MP_VMATH_MODULO:
      return MP_F3(mp_nl_safe_fmod(a.x, b.x), mp_nl_safe_fmod(a.y, b.y), mp_nl_safe_fmod(a.z, b.z));
    case MP_VMATH_WRAP:
      return MP_F3(mp_nl_wrap(a.x, b.x, c.x), mp_nl_wrap(a.y, b.y, c.y), mp_nl_wrap(a.z, b.z, c.z));
    case MP_VMATH_SNAP:
      return MP_F3(b.x != 0.0f ? floor(a.x / b.x) * b.x : 0.0f, b.y != 0.0f ? floor(a.y / b.y) * b.y : 0.0f,
                      b.z != 0.0f ? floor(a.z / b.z) * b.z : 0.0f);
    case MP_VMATH_SINE: return MP_F3(sin(a.x), sin(a.y), sin(a.z));
    case MP_VMATH_COSINE: return MP_F3(cos(a.x), cos(a.y), cos(a.z));
    case MP_VMATH_TANGENT: return MP_F3(tan(a.x), tan(a.y), tan(a.z));
  }
  return MP_F3(0.0f, 0.0f, 0.0f);
}

/* ---- Mix (color blend modes) ---------------------------------------------- */
#define MP_BLEND_MIX 0
#define MP_BLEND_ADD 1
#define MP_BLEND_MULTIPLY 2
#define MP_BLEND_SUBTRACT 3
#define MP_BLEND_SCREEN 4
#define MP_BLEND_DIVIDE 5
#define MP_BLEND_DIFFERENCE 6
#define MP_BLEND_DARKEN 7
#define MP_BLEND_LIGHTEN 8
#define MP_BLEND_OVERLAY 9
#define MP_BLEND_DODGE 10
#define MP_BLEND_BURN 11
#define MP_BLEND_SOFT_LIGHT 12
#define MP_BLEND_LINEAR_LIGHT 13
#define MP_BLEND_EXCLUSION 14
#define MP_BLEND_HUE 15
#define MP_BLEND_SATURATION 16
#define MP_BLEND_VALUE 17
#define MP_BLEND_COLOR 18

/* RGB <-> HSV with hue in [0, 1), the conversion Blender's colour nodes use:
 * a grey (zero saturation) has hue 0, and hue 1 wraps to 0. */
MP_INLINE float3 mp_rgb_to_hsv(float3 c) {
  float cmax = fmax(c.x, fmax(c.y, c.z)), cmin = fmin(c.x, fmin(c.y, c.z));
  float delta = cmax - cmin;
  float s = cmax != 0.0f ? delta / cmax : 0.0f;
  float h = 0.0f;
  if (s != 0.0f) {
    float3 k = (MP_F3(cmax, cmax, cmax) - c) / delta;
    if (c.x == cmax) h = k.z - k.y;
    else if (c.y == cmax) h = 2.0f + k.x - k.z;
    else h = 4.0f + k.y - k.x;
    h /= 6.0f;
    if (h < 0.0f) h += 1.0f;
  }
  return MP_F3(h, s, cmax);
}

MP_INLINE float3 mp_hsv_to_rgb(float3 hsv) {
  float h = hsv.x, s = hsv.y, v = hsv.z;
  if (s == 0.0f) return MP_F3(v, v, v);
  if (h == 1.0f) h = 0.0f;
  h *= 6.0f;
  float i = floor(h), f = h - i;
  float p = v * (1.0f - s), q = v * (1.0f - s * f), t = v * (1.0f - s * (1.0f - f));
  switch ((int)i) {
    case 0: return MP_F3(v, t, p);
    case 1: return MP_F3(q, v, p);
    case 2: return MP_F3(p, v, t);
    case 3: return MP_F3(p, q, v);
    case 4: return MP_F3(t, p, v);
  }
  return MP_F3(v, p, q);
}

/* Hue, Saturation, Value and Color blend modes: take some HSV channels from b.
 * Hue and Color leave a unchanged where b is grey (its hue is undefined);
 * Saturation leaves a grey a unchanged. */
MP_INLINE float3 mp_blend_hsv(int mode, float t, float3 a, float3 b) {
  float3 hb = mp_rgb_to_hsv(b), ha = mp_rgb_to_hsv(a);
  if (mode == MP_BLEND_VALUE) {
    ha.z = (1.0f - t) * ha.z + t * hb.z;
    return mp_hsv_to_rgb(ha);
  }
  if (mode == MP_BLEND_SATURATION) {
    if (ha.y == 0.0f) return a;
    ha.y = (1.0f - t) * ha.y + t * hb.y;
    return mp_hsv_to_rgb(ha);
  }
  if (hb.y == 0.0f) return a;
  ha.x = hb.x;
  if (mode == MP_BLEND_COLOR) ha.y = hb.y;
  return (1.0f - t) * a + t * mp_hsv_to_rgb(ha);
}

/* Hue/Saturation/Value node: hue shifted (0.5 is no shift), saturation
 * scaled and clamped to [0, 1], value scaled, blended with the input by fac
 * and kept non-negative. */
MP_INLINE float3 mp_hue_saturation(float hue, float saturation, float value, float fac, float3 color) {
  float3 hsv = mp_rgb_to_hsv(color);
  float hx = hsv.x + hue + 0.5f;
  hsv.x = hx - floor(hx);
  hsv.y = fmin(fmax(hsv.y * saturation, 0.0f), 1.0f);
  hsv.z *= value;
  float3 out = fac * mp_hsv_to_rgb(hsv) + (1.0f - fac) * color;
  return fmax(out, MP_F3(0.0f, 0.0f, 0.0f));
}

MP_INLINE float mp_nl_overlay(float t, float a, float b) {
  float tm = 1.0f - t;
  return a < 0.5f ? a * (tm + 2.0f * t * b) : 1.0f - (tm + 2.0f * t * (1.0f - b)) * (1.0f - a);
}
MP_INLINE float mp_nl_dodge(float t, float a, float b) {
  if (a == 0.0f) return a;
  float tmp = 1.0f - t * b;
  if (tmp <= 0.0f) return 1.0f;
  tmp = a / tmp;
  return tmp > 1.0f ? 1.0f : tmp;
}
MP_INLINE float mp_nl_burn(float t, float a, float b) {
  float tmp = (1.0f - t) + t * b;
  if (tmp <= 0.0f) return 0.0f;
  tmp = 1.0f - (1.0f - a) / tmp;
  return tmp < 0.0f ? 0.0f : tmp > 1.0f ? 1.0f : tmp;
}
MP_INLINE float mp_nl_soft_light(float t, float a, float b) {
  float scr = 1.0f - (1.0f - b) * (1.0f - a);
  return (1.0f - t) * a + t * ((1.0f - a) * b * a + a * scr);
}

MP_INLINE float3 mp_blend(int mode, float t, float3 a, float3 b) {
  float tm = 1.0f - t;
  switch (mode) {
    case MP_BLEND_MIX: return tm * a + t * b;
    case MP_BLEND_ADD: return a + t * b;
    case MP_BLEND_MULTIPLY: return a * (tm + t * b);
    case MP_BLEND_SUBTRACT: return a - t * b;
    case MP_BLEND_SCREEN:
      return MP_F3(1.0f, 1.0f, 1.0f) - (MP_F3(tm, tm, tm) + t * (MP_F3(1.0f, 1.0f, 1.0f) - b)) *
                                           (MP_F3(1.0f, 1.0f, 1.0f) - a);
    case MP_BLEND_DIVIDE:
      return MP_F3(b.x != 0.0f ? tm * a.x + t * a.x / b.x : a.x, b.y != 0.0f ? tm * a.y + t * a.y / b.y : a.y,
                      b.z != 0.0f ? tm * a.z + t * a.z / b.z : a.z);
    case MP_BLEND_DIFFERENCE: {
      float3 d = a - b;
      return tm * a + t * MP_F3(fabs(d.x), fabs(d.y), fabs(d.z));
    }
    case MP_BLEND_EXCLUSION: {
      float3 e = a + b - 2.0f * a * b;
      return tm * a + t * fmax(e, MP_F3(0.0f, 0.0f, 0.0f));
    }
    case MP_BLEND_DARKEN: return tm * a + t * fmin(a, b);
    case MP_BLEND_LIGHTEN: return tm * a + t * fmax(a, b);
    case MP_BLEND_OVERLAY: return MP_F3(mp_nl_overlay(t, a.x, b.x), mp_nl_overlay(t, a.y, b.y), mp_nl_overlay(t, a.z, b.z));
    case MP_BLEND_DODGE: return MP_F3(mp_nl_dodge(t, a.x, b.x), mp_nl_dodge(t, a.y, b.y), mp_nl_dodge(t, a.z, b.z));
    case MP_BLEND_BURN: return MP_F3(mp_nl_burn(t, a.x, b.x), mp_nl_burn(t, a.y, b.y), mp_nl_burn(t, a.z, b.z));
    case MP_BLEND_SOFT_LIGHT:
      return MP_F3(mp_nl_soft_light(t, a.x, b.x), mp_nl_soft_light(t, a.y, b.y), mp_nl_soft_light(t, a.z, b.z));
    case MP_BLEND_LINEAR_LIGHT: return a + t * (2.0f * b - MP_F3(1.0f, 1.0f, 1.0f));
    case MP_BLEND_HUE:
    case MP_BLEND_SATURATION:
    case MP_BLEND_VALUE:
    case MP_BLEND_COLOR: return mp_blend_hsv(mode, t, a, b);
  }
  return a;
}

MP_INLINE float3 mp_nl_clamp01_3(float3 c) {
  return MP_F3(mp_nl_clamp01(c.x), mp_nl_clamp01(c.y), mp_nl_clamp01(c.z));
}

/* ---- Map Range ------------------------------------------------------------ */
#define MP_RANGE_LINEAR 0
#define MP_RANGE_STEPPED 1
#define MP_RANGE_SMOOTHSTEP 2
#define MP_RANGE_SMOOTHERSTEP 3

MP_INLINE float mp_map_range(int mode, float value, float from_min, float from_max, float to_min, float to_max,
                             float steps, int clamp_result) {
  float factor = 0.0f;
  if (from_max != from_min) {
    float f = (value - from_min) / (from_max - from_min);
    if (mode == MP_RANGE_LINEAR) {
      factor = f;
    } else if (mode == MP_RANGE_STEPPED) {
      factor = steps > 0.0f ? floor(f * (steps + 1.0f)) / steps : 0.0f;
    } else {
      float t = mp_nl_clamp01(f);
      factor = mode == MP_RANGE_SMOOTHSTEP ? t * t * (3.0f - 2.0f * t) : t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
    }
  }
  float r = to_min + factor * (to_max - to_min);
  if (clamp_result && mode <= MP_RANGE_STEPPED)
    r = to_max > to_min ? fmin(fmax(r, to_min), to_max) : fmin(fmax(r, to_max), to_min);
  return r;
}

/* Vector Map Range: each component mapped on its own (steps per component). */
MP_INLINE float3 mp_map_range3(int mode, float3 v, float3 from_min, float3 from_max, float3 to_min, float3 to_max,
                               float3 steps, int clamp_result) {
  return MP_F3(mp_map_range(mode, v.x, from_min.x, from_max.x, to_min.x, to_max.x, steps.x, clamp_result),
               mp_map_range(mode, v.y, from_min.y, from_max.y, to_min.y, to_max.y, steps.y, clamp_result),
               mp_map_range(mode, v.z, from_min.z, from_max.z, to_min.z, to_max.z, steps.z, clamp_result));
}

/* ---- Clamp ---------------------------------------------------------------- */
MP_INLINE float mp_clamp_node(int range_mode, float value, float lo, float hi) {
  if (range_mode && lo > hi) return fmin(fmax(value, hi), lo);
  return fmin(fmax(value, lo), hi);
}

/* ---- Mapping: location, Euler XYZ rotation, scale -------------------------- */
#define MP_MAPPING_POINT 0
#define MP_MAPPING_TEXTURE 1
#define MP_MAPPING_VECTOR 2
#define MP_MAPPING_NORMAL 3

MP_INLINE float3 mp_mapping(int type, float3 v, float3 location, float3 rotation, float3 scale) {
  switch (type) {
    case MP_MAPPING_POINT: return mp_nl_euler_rotate(v * scale, rotation, 0) + location;
    case MP_MAPPING_TEXTURE:
      return MP_F3(mp_nl_safe_div(1.0f, scale.x), mp_nl_safe_div(1.0f, scale.y), mp_nl_safe_div(1.0f, scale.z)) *
             mp_nl_euler_rotate(v - location, rotation, 1);
    case MP_MAPPING_VECTOR: return mp_nl_euler_rotate(v * scale, rotation, 0);
    case MP_MAPPING_NORMAL:
      return mp_nl_safe_normalize(mp_nl_euler_rotate(
          v * MP_F3(mp_nl_safe_div(1.0f, scale.x), mp_nl_safe_div(1.0f, scale.y), mp_nl_safe_div(1.0f, scale.z)),
          rotation, 0));
  }
  return v;
}

/* ---- Color Ramp: stops sorted by position, RGB mode ------------------------ */
#define MP_RAMP_LINEAR 0
#define MP_RAMP_CONSTANT 1
#define MP_RAMP_EASE 2

MP_INLINE float4 mp_color_ramp(int interpolation, int count, const float* positions, const float4* colors, float t) {
  if (count <= 0) return MP_F4(0.0f, 0.0f, 0.0f, 1.0f);
  if (t <= positions[0]) return colors[0];
  for (int k = 1; k < count; ++k) {
    if (t < positions[k]) {
      if (interpolation == MP_RAMP_CONSTANT) return colors[k - 1];
      float span = positions[k] - positions[k - 1];
      float f = span > 0.0f ? (t - positions[k - 1]) / span : 0.0f;
      if (interpolation == MP_RAMP_EASE) f = f * f * (3.0f - 2.0f * f);
      return colors[k - 1] + (colors[k] - colors[k - 1]) * f;
    }
  }
  return colors[count - 1];
}

/* Luminance of a scene-linear Rec.709 color (RGB to BW). */
MP_INLINE float mp_rgb_to_bw(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

#endif
