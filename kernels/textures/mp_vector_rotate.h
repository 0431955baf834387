/* Rotations the shader nodes share: Blender's Euler XYZ rotation (Mapping,
 * Vector Rotate) and the Vector Rotate node itself, as Cycles evaluates it
 * (svm vector_rotate: about a centre, by an axis and angle, about X, Y or Z,
 * or by Euler angles; Invert turns the other way). Compiles as OpenCL C and
 * C++ (include mp_compat.h first); the texture probe checks it against
 * Blender. */
#ifndef MP_VECTOR_ROTATE_H
#define MP_VECTOR_ROTATE_H

#include "core/mp_compat.h"

/* Rotation by Euler angles, X first, then Y, then Z (Blender's XYZ order). */
MP_INLINE float3 mp_nl_euler_rotate(float3 v, float3 r, int inverse) {
  float cx = cos(r.x), sx = sin(r.x), cy = cos(r.y), sy = sin(r.y), cz = cos(r.z), sz = sin(r.z);
  /* Rows of R = Rz * Ry * Rx. */
  float3 r0 = MP_F3(cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz);
  float3 r1 = MP_F3(cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz);
  float3 r2 = MP_F3(-sy, cy * sx, cy * cx);
  if (!inverse) return MP_F3(dot(r0, v), dot(r1, v), dot(r2, v));
  return v.x * r0 + v.y * r1 + v.z * r2; /* the transpose */
}

/* Vector Rotate's rotation types (Blender's order). */
#define MP_ROTATE_AXIS_ANGLE 0
#define MP_ROTATE_X 1
#define MP_ROTATE_Y 2
#define MP_ROTATE_Z 3
#define MP_ROTATE_EULER_XYZ 4

/* Rodrigues' rotation of p about the unit axis k by angle a (right-handed). */
MP_INLINE float3 mp_rotate_about_axis(float3 p, float3 k, float a) {
  float c = cos(a), s = sin(a);
  return p * c + cross(k, p) * s + k * (dot(k, p) * (1.0f - c));
}

/* A zero axis leaves the vector where it is, as in Cycles. */
MP_INLINE float3 mp_vector_rotate(int type, int invert, float3 v, float3 center, float3 axis, float angle,
                                  float3 euler) {
  if (type == MP_ROTATE_EULER_XYZ) return mp_nl_euler_rotate(v - center, euler, invert) + center;
  if (type == MP_ROTATE_X) axis = MP_F3(1.0f, 0.0f, 0.0f);
  if (type == MP_ROTATE_Y) axis = MP_F3(0.0f, 1.0f, 0.0f);
  if (type == MP_ROTATE_Z) axis = MP_F3(0.0f, 0.0f, 1.0f);
  float len = sqrt(dot(axis, axis));
  if (!(len != 0.0f)) return v;
  return mp_rotate_about_axis(v - center, axis / len, invert ? -angle : angle) + center;
}

#endif
