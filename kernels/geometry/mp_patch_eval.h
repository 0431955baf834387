/* Evaluation of a device patch (layout in mp_patch.h): position and both first
 * derivatives at (u, v) in [0,1]^2. Compiles as OpenCL C 1.2 and as C++17
 * (include mp_compat.h and mp_patch.h first).
 *
 * Bicubic Bezier (MP_PATCH_BEZIER):
 *   P(u,v) = sum_{i,j} B_i(u) B_j(v) b_ij,   b_ij = cp[4*j + i],
 *   B_0 = (1-t)^3, B_1 = 3t(1-t)^2, B_2 = 3t^2(1-t), B_3 = t^3.
 *
 * Gregory (MP_PATCH_GREGORY), the cubic Gregory patch of OpenSubdiv's
 * Gregory-basis end caps (Loop, Schaefer, Ni, Castano 2009, "Approximating
 * subdivision surfaces with Gregory patches for hardware tessellation";
 * OpenSubdiv Far patchBasis, EvalBasisGregory): the same tensor product, but
 * each interior point is a rational blend of two face points,
 *
 *   I(u,v) = w q_u + (1 - w) q_v,   w = d_u / (d_u + d_v),
 *
 * where d_u is the parametric distance to the nearer u = const edge
 * (u or 1-u) and d_v the distance to the nearer v = const edge (v or 1-v).
 * q_u (stored in the net) is the face point that shapes the cross-boundary
 * derivative along the nearer v = const edge (the edge where d_v = 0 and the
 * blend picks q_u); q_v (the partner, cp[16 + k]) shapes it along the nearer
 * u = const edge. In OpenSubdiv's 20-point ordering these are (net, partner):
 * (1,1) = (F0+, F0-), (2,1) = (F1-, F1+), (1,2) = (F3-, F3+), (2,2) = (F2+, F2-).
 *
 * The derivatives include the derivative of the rational weight,
 *   dI/du = (dw/du)(q_u - q_v),  dw/du =  s_u d_v / (d_u + d_v)^2,
 *   dI/dv = (dw/dv)(q_u - q_v),  dw/dv = -s_v d_u / (d_u + d_v)^2,
 * with s_u = d(d_u)/du = +1 for i = 1 and -1 for i = 2 (likewise s_v), so they
 * are the exact derivatives of the evaluated position. (OpenSubdiv's own
 * evaluation drops this term unless it is built with
 * OPENSUBDIV_GREGORY_EVAL_TRUE_DERIVATIVES; both agree on the patch edges.)
 *
 * At a patch corner d_u + d_v = 0 and w is 0/0; there the interior point has
 * zero Bezier weight and zero derivative weight, so any w gives the limit
 * value: w = 1/2 is used (and the weight derivatives are dropped within 1e-12
 * of the corner, where their contribution is below 1e-11 of |q_u - q_v|).
 *
 * For MP_PATCH_BEZIER the partners are ignored (the blend degenerates to the
 * net point), so one code path serves both types without divergent branches.
 */
#ifndef MP_PATCH_EVAL_H
#define MP_PATCH_EVAL_H

/* Index in the 4x4 net of interior point k (0..3): (1,1), (2,1), (1,2), (2,2). */
MP_INLINE int mp_interior_index(int k) { return k < 2 ? 5 + k : 7 + k; }

/* Index of the partner of interior point k (0..3) of a Gregory patch. */
MP_INLINE int mp_partner_index(int k) { return MP_PATCH_POINTS - 4 + k; }

/* Cubic Bernstein polynomials and their derivatives at t. */
MP_INLINE void mp_bezier_basis(float t, float* b, float* db) {
  float s = 1.0f - t;
  b[0] = s * s * s;
  b[1] = 3.0f * t * s * s;
  b[2] = 3.0f * t * t * s;
  b[3] = t * t * t;
  db[0] = -3.0f * s * s;
  db[1] = 3.0f * s * (s - 2.0f * t);
  db[2] = 3.0f * t * (2.0f * s - t);
  db[3] = 3.0f * t * t;
}

/* Interior point k at (u, v), blended with its partner for Gregory patches,
 * and its own derivatives (zero for Bezier patches). */
MP_INLINE float3 mp_interior_point(const MP_GLOBAL float4* cp, uint type, int k, float u, float v,
                                   float3* dIdu, float3* dIdv) {
  int net = mp_interior_index(k);
  int partner = type == MP_PATCH_GREGORY ? mp_partner_index(k) : net;
  float3 qu = MP_XYZ(cp[net]);
  float3 qv = MP_XYZ(cp[partner]);
  float su = (k & 1) ? -1.0f : 1.0f;           /* d(d_u)/du */
  float sv = (k & 2) ? -1.0f : 1.0f;           /* d(d_v)/dv */
  float du = (k & 1) ? 1.0f - u : u;
  float dv = (k & 2) ? 1.0f - v : v;
  float sum = du + dv;
  float inv = sum > 1e-12f ? 1.0f / sum : 0.0f;
  float w = sum > 1e-12f ? du * inv : 0.5f;
  float3 diff = qu - qv;
  *dIdu = (su * dv * inv * inv) * diff;
  *dIdv = (-sv * du * inv * inv) * diff;
  return qv + w * diff;
}

/* One row j of the net: sum_i B_i(u) c_i and sum_i B_i'(u) c_i. */
MP_INLINE float3 mp_bezier_row(float3 c0, float3 c1, float3 c2, float3 c3, const float* bu,
                               const float* dbu, float3* row_du) {
  *row_du = dbu[0] * c0 + dbu[1] * c1 + dbu[2] * c2 + dbu[3] * c3;
  return bu[0] * c0 + bu[1] * c1 + bu[2] * c2 + bu[3] * c3;
}

MP_INLINE void mp_eval_patch(const MP_GLOBAL float4* cp, uint type, float u, float v, float3* P,
                             float3* dPdu, float3* dPdv) {
  float bu[4], dbu[4], bv[4], dbv[4];
  mp_bezier_basis(u, bu, dbu);
  mp_bezier_basis(v, bv, dbv);

  float3 dI0u, dI0v, dI1u, dI1v, dI2u, dI2v, dI3u, dI3v;
  float3 i0 = mp_interior_point(cp, type, 0, u, v, &dI0u, &dI0v);
  float3 i1 = mp_interior_point(cp, type, 1, u, v, &dI1u, &dI1v);
  float3 i2 = mp_interior_point(cp, type, 2, u, v, &dI2u, &dI2v);
  float3 i3 = mp_interior_point(cp, type, 3, u, v, &dI3u, &dI3v);

  float3 r0u, r1u, r2u, r3u;
  float3 r0 = mp_bezier_row(MP_XYZ(cp[0]), MP_XYZ(cp[1]), MP_XYZ(cp[2]), MP_XYZ(cp[3]), bu, dbu, &r0u);
  float3 r1 = mp_bezier_row(MP_XYZ(cp[4]), i0, i1, MP_XYZ(cp[7]), bu, dbu, &r1u);
  float3 r2 = mp_bezier_row(MP_XYZ(cp[8]), i2, i3, MP_XYZ(cp[11]), bu, dbu, &r2u);
  float3 r3 = mp_bezier_row(MP_XYZ(cp[12]), MP_XYZ(cp[13]), MP_XYZ(cp[14]), MP_XYZ(cp[15]), bu, dbu, &r3u);

  *P = bv[0] * r0 + bv[1] * r1 + bv[2] * r2 + bv[3] * r3;
  /* Product rule for the (u, v)-dependent interior points (zero for Bezier). */
  float3 interior_du = bv[1] * (bu[1] * dI0u + bu[2] * dI1u) + bv[2] * (bu[1] * dI2u + bu[2] * dI3u);
  float3 interior_dv = bv[1] * (bu[1] * dI0v + bu[2] * dI1v) + bv[2] * (bu[1] * dI2v + bu[2] * dI3v);
  *dPdu = bv[0] * r0u + bv[1] * r1u + bv[2] * r2u + bv[3] * r3u + interior_du;
  *dPdv = dbv[0] * r0 + dbv[1] * r1 + dbv[2] * r2 + dbv[3] * r3 + interior_dv;
}

#endif
