/* Ribbons: a strand segment (MP_PATCH_CURVE, layout in mp_patch.h) drawn as
 * a flat strip that turns to face the view evaluating it, the camera or a
 * light, as RenderMan draws RiCurves without normals and Cycles its Rounded
 * Ribbons (a ribbon facing each ray). v runs along the centre line C(v), a
 * cubic Bezier, u across it, from one side to the other:
 *
 *   P(u, v) = C(v) + h r(v) s(v),   h = 2u - 1,
 *   s = (C' x w) / |C' x w|,        w towards the eye from C (or the
 *                                   orthographic view's direction),
 *
 * with r(v) the radius, cubic in the same basis. The strip is 2 r wide, as
 * the tube it stands for seen from the eye. Its shading normal is that
 * tube's at the same offset (Cycles' rounded ribbon normal),
 *
 *   N = h s + sqrt(1 - h^2) f,   f = s x C' / |s x C'|, facing the eye,
 *
 * so lobes that read the offset across a fibre from N (mp_hair.h) see the
 * offset h. In a light's view the strip also moves a radius away from the
 * light (MpPlacement.push): every point of the camera's strip of the same
 * strand then lies in front of it, as every point of a round fibre's near
 * half lies in front of its far half, so a ribbon does not shadow itself
 * (Cycles' shadow rays skip the segment they leave); what it shadows
 * moves by a radius along the light, well below a pixel for hair. Evaluation is in camera space: the segment's points are placed
 * first (mp_instance.h), then turned towards the placement's eye, so an
 * instance's ribbons face the view as its own copies would. The derivatives
 * are those of the strip at fixed s (the turn of s along v is left out:
 * they steer rates and texture differences only).
 *
 * Compiles as OpenCL C and C++ (include mp_compat.h, mp_patch.h,
 * mp_types.h, mp_patch_eval.h and mp_instance.h first). */
#ifndef MP_RIBBON_H
#define MP_RIBBON_H

/* Placed radius control value j: the mean length of the three offsets. */
MP_INLINE float mp_ribbon_radius(const MP_GLOBAL float4* cp, int j, const MpPlacement* place) {
  float3 c = MP_XYZ(cp[4 * j]);
  float r = 0.0f;
  for (int k = 1; k <= 3; ++k) r += length(mp_place_vector(place, MP_XYZ(cp[4 * j + k]) - c));
  return r * (1.0f / 3.0f);
}

/* Where across a strip diced n micropolygons across (a power of two) its
 * vertices are shaded, as a fraction of their offsets h: shading is
 * interpolated linearly between vertices, so a strip one micropolygon
 * across shaded at its edges (normals square to the view) would average
 * two grazing values where the round fibre it stands for averages pi/4 of
 * its facing value. Shading at k h instead, k chosen so that the linear
 * interpolation of the facing term sqrt(1 - (k h)^2) over the n + 1
 * vertices averages pi/4 exactly, keeps a thin strand as bright as Cycles'
 * ribbon (whose samples take the rounded normal at every offset), and
 * light from the side within 6 % for n = 1 (0.31 against 0.25), less
 * beyond. */
MP_INLINE float mp_ribbon_shading_scale(uint n) {
  return n <= 1u ? 0.619f : n == 2u ? 0.8211f : n <= 4u ? 0.9289f : n <= 8u ? 0.9734f : n <= 16u ? 0.9901f : 0.9964f;
}

/* Position and derivatives at (u, v), placed and facing the placement's
 * eye, and the rounded shading normal (unit) at shade_scale times the
 * offset (mp_ribbon_shading_scale; 1: at the vertex itself). */
MP_INLINE void mp_eval_ribbon_shaded(const MP_GLOBAL float4* cp, float u, float v, const MpPlacement* place,
                                     float shade_scale, float3* P, float3* dPdu, float3* dPdv, float3* N) {
  float b[4], db[4];
  mp_bezier_basis(v, b, db);
  float3 c = MP_F3(0.0f, 0.0f, 0.0f), dc = MP_F3(0.0f, 0.0f, 0.0f);
  float r = 0.0f;
  for (int j = 0; j < 4; ++j) {
    float3 q = MP_XYZ(cp[4 * j]);
    c += b[j] * q;
    dc += db[j] * q;
    r += b[j] * mp_ribbon_radius(cp, j, place);
  }
  c = mp_place_point(place, c);
  float3 t = mp_place_vector(place, dc);
  float3 w = place->eye.w > 0.0f ? MP_XYZ(place->eye) - c : MP_XYZ(place->eye);
  float3 s = cross(t, w);
  float ls = length(s);
  if (!(ls > 1e-20f * length(t) * length(w))) {
    /* Seen along the strand (or a vanishing tangent): any side will do. */
    float3 a = length(t) > 0.0f ? t : w;
    s = cross(a, fabs(a.x) < 0.6f * length(a) ? MP_F3(1.0f, 0.0f, 0.0f) : MP_F3(0.0f, 1.0f, 0.0f));
    ls = length(s);
  }
  s = ls > 0.0f ? s / ls : MP_F3(1.0f, 0.0f, 0.0f);
  float h = 2.0f * u - 1.0f;
  float lw = length(w);
  *P = c + (h * r) * s - (place->push > 0.0f && lw > 0.0f ? r / lw : 0.0f) * w;
  *dPdu = (2.0f * r) * s;
  *dPdv = t;
  float3 f = cross(s, t);
  float lf = length(f);
  if (lf > 0.0f) f = f / lf;
  else f = place->eye.w > 0.0f ? normalize(w) : MP_XYZ(place->eye);
  float hs = h * shade_scale;
  *N = hs * s + sqrt(fmax(0.0f, 1.0f - hs * hs)) * f;
}

MP_INLINE void mp_eval_ribbon(const MP_GLOBAL float4* cp, float u, float v, const MpPlacement* place, float3* P,
                              float3* dPdu, float3* dPdv, float3* N) {
  mp_eval_ribbon_shaded(cp, u, v, place, 1.0f, P, dPdu, dPdv, N);
}

/* Position and derivatives of any patch at (u, v), placed: a ribbon faces
 * the placement's eye; other patches are evaluated in their own space and
 * then placed. */
MP_INLINE void mp_eval_placed(const MP_GLOBAL float4* cp, uint type, float u, float v, const MpPlacement* place,
                              float3* P, float3* dPdu, float3* dPdv) {
  if (type == MP_PATCH_CURVE) {
    float3 n;
    mp_eval_ribbon(cp, u, v, place, P, dPdu, dPdv, &n);
    return;
  }
  mp_eval_patch(cp, type, u, v, P, dPdu, dPdv);
  *P = mp_place_point(place, *P);
  *dPdu = mp_place_vector(place, *dPdu);
  *dPdv = mp_place_vector(place, *dPdv);
}

#endif
