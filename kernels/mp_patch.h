/* Device patch layout, shared by the host patch builders and the kernels.
 *
 * Every surface reaches the device as a bicubic patch of MP_PATCH_POINTS
 * control points (float4, xyz used; camera space on the device):
 *
 *   cp[4*j + i], i along u, j along v (i, j in 0..3): a bicubic Bezier net.
 *   cp[16 + k], k = 0..3: the partner of interior point (1,1), (2,1), (1,2), (2,2).
 *
 * For MP_PATCH_BEZIER the partners equal the interior points, so the patch is an
 * ordinary Bezier patch. Bilinear faces are degree-elevated into this form, and
 * B-spline/Catmull-Rom/Hermite nets are converted to it on the host.
 *
 * For MP_PATCH_GREGORY (OpenSubdiv's Gregory-basis end caps around extraordinary
 * vertices) each interior point is a rational blend of the point and its partner,
 * with weights that depend on (u, v); see mp_patch_eval.h. Each interior point of
 * the blend lies on the segment between the point and its partner, which is what
 * the conservative bounds in mp_bound.h rely on.
 */
#ifndef MP_PATCH_H
#define MP_PATCH_H

#define MP_PATCH_POINTS 20
#define MP_PATCH_BEZIER 0u
#define MP_PATCH_GREGORY 1u

/* PatchInfo (uint4): x = type, y = material index, z = flags, w = primitive id
 * (the face or patch index in its object, used to make sample ids stable). */
#define MP_PATCH_DOUBLE_SIDED 1u
#define MP_PATCH_FLIP_ORIENTATION 2u

/* Interior point indices in the 4x4 net and the index of their partners. */
#define MP_INTERIOR_0 5
#define MP_INTERIOR_1 6
#define MP_INTERIOR_2 9
#define MP_INTERIOR_3 10

#endif
