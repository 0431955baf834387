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
/* MP_PATCH_CURVE: one cubic segment of a strand, drawn as a ribbon that
 * faces each view (RenderMan's RiCurves, Cycles' Rounded Ribbons; see
 * mp_ribbon.h). v runs along the strand, u across it. Row j (j = 0..3) holds
 * the segment's j-th Bezier control point C_j = cp[4*j] and three points
 * cp[4*j + k] = C_j + r_j e_k (k = 1, 2, 3; e_k the axes), r_j the radius
 * control value: any affine placement carries the radius with the points,
 * as the mean length of the three offsets. The partners cp[16], cp[17] (and
 * again cp[18], cp[19]) are the lower and upper corners of a box around the
 * whole ribbon in any orientation, so a hull of all 20 points bounds it. */
#define MP_PATCH_CURVE 2u

/* PatchInfo (uint4): x = type, y = material index, z = flags, w = primitive id
 * (the face or patch index in its object, used to make sample ids stable).
 * Flags bits 8-31 hold the patch's object index (DeviceObject, mp_types.h). */
#define MP_PATCH_DOUBLE_SIDED 1u
#define MP_PATCH_FLIP_ORIENTATION 2u
#define MP_PATCH_SMOOTH_NORMALS 4u /* has corner normals (MP_PATCH_NORMALS) */
#define MP_PATCH_NO_SHADOW 8u      /* casts no shadows (not in the lights' views) */
#define MP_PATCH_NO_CAMERA 16u     /* not seen by the camera (still casts shadows) */
/* u runs around a round section (a hair tube's quarter turn, scene/curves.h):
 * the normal turns 90 degrees across u however few pixels the patch covers,
 * so every view's grids keep MP_ROUND_MIN_RATE micropolygons across u. With
 * one per quarter, the vertices a thin tube is shaded at are its silhouettes
 * and its middle, and interpolating between them darkens a lit tube by up to
 * a fifth (2/pi against pi/4 for light from the eye); and a light's view of
 * the tube is a square, whose shadow is on average a tenth narrower than
 * the tube's (a head of hair's shadows 5 % too light under a sun). */
#define MP_PATCH_ROUND_U 32u
#define MP_ROUND_MIN_RATE 4u
/* Flags that belong to a patch's shape rather than to the object placing it. */
#define MP_PATCH_SHAPE_FLAGS (MP_PATCH_SMOOTH_NORMALS | MP_PATCH_ROUND_U)
#define MP_PATCH_OBJECT(flags) ((flags) >> 8)

/* The w of the first control point is the patch's displacement bound: how
 * far (camera space) its material's displacement can move the surface. */
#define MP_PATCH_DISPLACEMENT_BOUND(cp) ((cp)[0].w)
/* Motion blur: how far (camera x, y, z) the patch's control points move
 * away from these, the shutter centre's, during the shutter. */
#define MP_PATCH_MOTION_REACH(cp) MP_F3((cp)[1].w, (cp)[2].w, (cp)[3].w)

/* Patch edges. Edge e of a patch is the boundary curve v = 0 (e = 0), u = 1
 * (e = 1), v = 1 (e = 2) or u = 0 (e = 3), parametrised by u (e = 0, 2) or v
 * (e = 1, 3). Neighbouring patches evaluate a shared edge from one stored
 * cubic Bezier curve, so both produce bit-identical points (mp_surface.h).
 * A curve is MP_CURVE_FLOAT4S float4: its 4 control points, then 4 control
 * points of a cubic that interpolates the surface normal along the edge
 * (sampled from one of the patches), so displacement along the normal moves
 * shared edge vertices identically from both sides. PatchEdges holds 8 uints per patch, two per edge:
 * a curve reference (curve index << 1 | 1 if the curve runs against the
 * edge's parameter) and MP_NO_CURVE, or, for an edge whose neighbour side is
 * two patches of the next finer level (a transition edge), the references of
 * the halves t in [0, 1/2] and [1/2, 1]. */
#define MP_NO_CURVE 0xffffffffu
#define MP_EDGE_REFS 8
#define MP_CURVE_FLOAT4S 8

/* UV maps. Each patch has, per UV layer, its corner UVs in two float4:
 * (uv(0,0), uv(1,0)) and (uv(1,1), uv(0,1)), at patch_uvs[2 * (patch *
 * layers + layer)]. Inside the patch UVs are bilinear in the corners (exact
 * for flat faces and for OpenSubdiv's linearly interpolated face-varying
 * data); mp_patch_uv in mp_surface.h evaluates them watertight. */
#define MP_MAX_UV_LAYERS 8

/* Smooth shading normals: 4 float4 per patch at patch_normals[4 * patch],
 * the normals at corners (0,0), (1,0), (1,1), (0,1) (camera space on the
 * device, not normalised), interpolated bilinearly; all zero for a patch
 * shaded with its own surface normal (mp_patch_shading_normal). */
#define MP_PATCH_NORMALS 4

/* Interior point indices in the 4x4 net and the index of their partners. */
#define MP_INTERIOR_0 5
#define MP_INTERIOR_1 6
#define MP_INTERIOR_2 9
#define MP_INTERIOR_3 10

#endif
