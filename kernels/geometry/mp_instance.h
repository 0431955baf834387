/* Instances on the device (scene.h Prototype and Instance; DeviceInstance
 * in mp_types.h). A prototype's surface is stored once, in its own space,
 * as ordinary patches; each instance of it is a DeviceInstance whose
 * transform carries whatever is evaluated from those patches (positions,
 * derivatives, edge curves, shading normals) to camera space. Sub-patches
 * of an instance name it in SubPatch.instance; patches placed on their own
 * (MP_NO_INSTANCE) are in camera space already and pass unchanged.
 *
 * Bezier and Gregory patches are affine invariant, so evaluating in the
 * prototype's space and transforming the results is the surface the
 * instance's copy would be; both sides of an edge of one instance take the
 * same curve through the same transform, so its grids stay watertight.
 *
 * Roots: a view's roots are the patches placed on their own
 * [0, patch_count), then one per instance: the root of its surface's tree
 * of patches (DevicePatchNode). Bound & split opens a node whose box the
 * instance carries into the view (not culled by the frustum, the shadow
 * pages or the occlusion pyramid) into its two children, down to patches,
 * which go on as any patch does; (instance, patch) pairs are never listed,
 * and what a view cannot see is dropped a subtree at a time, the whole
 * instance first. Nodes never reach the dicer.
 *
 * Compiles as OpenCL C and C++. */
#ifndef MP_INSTANCE_H
#define MP_INSTANCE_H

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"

/* A transform to camera space: rows of a 3x4 matrix for points (and their
 * linear part for vectors), rows of the inverse transpose for normals. */
typedef struct {
  float4 r[3];
  float4 n[3];
  int placed; /* 0: the identity (patches placed on their own) */
  /* Where the view that evaluates the patch looks from, camera space: the
   * eye (w = 1) or, for an orthographic view, the unit direction towards it
   * (w = 0). Only ribbons (MP_PATCH_CURVE) read it; the camera's own eye
   * unless mp_place_facing says otherwise. */
  float4 eye;
  /* 1 in a light's view: ribbons move a radius away from the light
   * (mp_ribbon.h); 0 elsewhere. */
  float push;
} MpPlacement;

MP_INLINE MpPlacement mp_placement_none(void) {
  MpPlacement m;
  for (int k = 0; k < 3; ++k) m.r[k] = m.n[k] = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  m.placed = 0;
  m.eye = MP_F4(0.0f, 0.0f, 0.0f, 1.0f);
  m.push = 0.0f;
  return m;
}

MP_INLINE MpPlacement mp_placement_rows(const MP_GLOBAL float* rows, const MP_GLOBAL float* normal_rows) {
  MpPlacement m;
  for (int k = 0; k < 3; ++k) {
    m.r[k] = MP_F4(rows[4 * k], rows[4 * k + 1], rows[4 * k + 2], rows[4 * k + 3]);
    m.n[k] = MP_F4(normal_rows[4 * k], normal_rows[4 * k + 1], normal_rows[4 * k + 2], 0.0f);
  }
  m.placed = 1;
  m.eye = MP_F4(0.0f, 0.0f, 0.0f, 1.0f);
  m.push = 0.0f;
  return m;
}

/* The eye of view f (FrameParams: camera space -> its space by the rigid
 * rows `view`, looking down -z) for the ribbons a placement evaluates: the
 * view's origin, -R^T t, or for an orthographic view its +z axis, R^T z. */
MP_INLINE void mp_place_facing(MpPlacement* m, FrameParams f) {
  m->push = f.view_kind == MP_VIEW_SHADOW ? 1.0f : 0.0f;
  if (!f.has_view) {
    m->eye = f.ortho ? MP_F4(0.0f, 0.0f, 1.0f, 0.0f) : MP_F4(0.0f, 0.0f, 0.0f, 1.0f);
    return;
  }
  const float* v = f.view;
  if (f.ortho) {
    m->eye = MP_F4(v[8], v[9], v[10], 0.0f);
    return;
  }
  m->eye = MP_F4(-(v[0] * v[3] + v[4] * v[7] + v[8] * v[11]), -(v[1] * v[3] + v[5] * v[7] + v[9] * v[11]),
                 -(v[2] * v[3] + v[6] * v[7] + v[10] * v[11]), 1.0f);
}

/* The placement of a sub-patch's instance at the shutter's centre. */
MP_INLINE MpPlacement mp_instance_placement(const MP_GLOBAL DeviceInstance* instances, uint instance) {
  if (instance == MP_NO_INSTANCE) return mp_placement_none();
  return mp_placement_rows(instances[instance].to_camera, instances[instance].normal_to_camera);
}

/* ... at motion step `step`: its rows from instance_motion (3 float4 per
 * instance and step); normals keep the centre's (only positions move). */
MP_INLINE MpPlacement mp_instance_placement_at_step(const MP_GLOBAL DeviceInstance* instances,
                                                    const MP_GLOBAL float4* motion, uint instance_count,
                                                    uint instance, uint step) {
  MpPlacement m = mp_instance_placement(instances, instance);
  if (instance == MP_NO_INSTANCE) return m;
  const MP_GLOBAL float4* rows = motion + 3u * ((ulong)step * instance_count + instance);
  for (int k = 0; k < 3; ++k) m.r[k] = rows[k];
  return m;
}

MP_INLINE float3 mp_place_point(const MpPlacement* m, float3 p) {
  if (!m->placed) return p;
  return MP_F3(m->r[0].x * p.x + m->r[0].y * p.y + m->r[0].z * p.z + m->r[0].w,
               m->r[1].x * p.x + m->r[1].y * p.y + m->r[1].z * p.z + m->r[1].w,
               m->r[2].x * p.x + m->r[2].y * p.y + m->r[2].z * p.z + m->r[2].w);
}

MP_INLINE float3 mp_place_vector(const MpPlacement* m, float3 v) {
  if (!m->placed) return v;
  return MP_F3(m->r[0].x * v.x + m->r[0].y * v.y + m->r[0].z * v.z,
               m->r[1].x * v.x + m->r[1].y * v.y + m->r[1].z * v.z,
               m->r[2].x * v.x + m->r[2].y * v.y + m->r[2].z * v.z);
}

MP_INLINE float3 mp_place_normal(const MpPlacement* m, float3 n) {
  if (!m->placed) return n;
  return MP_F3(m->n[0].x * n.x + m->n[0].y * n.y + m->n[0].z * n.z,
               m->n[1].x * n.x + m->n[1].y * n.y + m->n[1].z * n.z,
               m->n[2].x * n.x + m->n[2].y * n.y + m->n[2].z * n.z);
}

/* Boxes of the prototype's space carried to camera space: a box that is a
 * point (a Bezier control point) as that point, exactly; any other by the
 * box around its transformed corners. */
MP_INLINE void mp_place_boxes(const MpPlacement* m, float3* lo, float3* hi, int count) {
  if (!m->placed) return;
  for (int k = 0; k < count; ++k) {
    float3 c = mp_place_point(m, 0.5f * (lo[k] + hi[k])), h = 0.5f * (hi[k] - lo[k]);
    float3 e = MP_F3(fabs(m->r[0].x) * h.x + fabs(m->r[0].y) * h.y + fabs(m->r[0].z) * h.z,
                     fabs(m->r[1].x) * h.x + fabs(m->r[1].y) * h.y + fabs(m->r[1].z) * h.z,
                     fabs(m->r[2].x) * h.x + fabs(m->r[2].y) * h.y + fabs(m->r[2].z) * h.z);
    if (h.x == 0.0f && h.y == 0.0f && h.z == 0.0f) {
      lo[k] = hi[k] = c;
    } else {
      lo[k] = c - e;
      hi[k] = c + e;
    }
  }
}

/* PatchInfo flags of a sub-patch's patch as its instance places it: the
 * instance's orientation flip and visibility added, its object in bits
 * 8-31 (MP_PATCH_OBJECT). */
MP_INLINE uint mp_placed_flags(const MP_GLOBAL uint* patch_info, const MP_GLOBAL DeviceInstance* instances,
                               uint patch, uint instance) {
  uint flags = patch_info[4 * (ulong)patch + 2];
  if (instance == MP_NO_INSTANCE) return flags;
  uint own = instances[instance].flags;
  return ((flags & 0xffu) ^ (own & MP_PATCH_FLIP_ORIENTATION)) | (own & (MP_PATCH_NO_CAMERA | MP_PATCH_NO_SHADOW)) |
         (instances[instance].object << 8);
}

/* Root q of a view (q < root_count): its patch, or its instance's tree's
 * root node, and its instance. */
MP_INLINE void mp_root_patch(uint q, uint patch_count, const MP_GLOBAL DeviceInstance* instances, uint* patch,
                             uint* instance) {
  if (q < patch_count) {
    *patch = q;
    *instance = MP_NO_INSTANCE;
    return;
  }
  *instance = q - patch_count;
  *patch = instances[q - patch_count].root;
}

/* The whole domain of a patch (or a node) as a sub-patch of `instance`,
 * split nowhere and no edge rated yet: a root, or a node's child. */
MP_INLINE void mp_whole_subpatch(uint patch, uint instance, uint info, SubPatch* sp) {
  sp->corner[0] = 0.0f, sp->corner[1] = 0.0f;
  sp->corner[2] = 1.0f, sp->corner[3] = 0.0f;
  sp->corner[4] = 1.0f, sp->corner[5] = 1.0f;
  sp->corner[6] = 0.0f, sp->corner[7] = 1.0f;
  sp->patch = patch;
  sp->instance = instance;
  sp->info = info;
  sp->rates = 0u;
}

/* A node's children as its sub-patch carries them from its classification
 * to its split (mp_bound.h): a node has no parametric domain, so its first
 * two corners hold them. */
MP_INLINE void mp_node_store_children(SubPatch* sp, const MP_GLOBAL DevicePatchNode* node) {
  sp->corner[0] = as_float(node->child[0]);
  sp->corner[1] = as_float(node->child[1]);
}

MP_INLINE uint mp_node_child(const SubPatch* sp, int k) { return as_uint(sp->corner[k]); }

/* An id for hashes that tell surfaces apart (sample keys, stochastic
 * opacity): the patch's, combined with its instance's. */
MP_INLINE uint mp_placed_patch_id(uint patch, uint instance) {
  return instance == MP_NO_INSTANCE ? patch : patch ^ (instance * 0x9e3779b9u + 0x7f4a7c15u);
}

#endif
