/* Records that cross the host/device boundary. Plain 4-byte scalars only, so
 * the C++ host and OpenCL C agree on the layout without padding rules. */
#ifndef MP_TYPES_H
#define MP_TYPES_H

#include "core/mp_compat.h"

/* A piece of a patch: the parametric quadrilateral with corners
 * (corner[2k], corner[2k+1]), k = 0..3, counter-clockwise in (u, v), of patch
 * `patch`. Edge k runs from corner k to corner k+1. `info` packs the split
 * depth (bits 0-7), once the sub-patch is diceable its grid size in
 * micropolygons (nu: bits 8-15, nv: bits 16-23), and the view it belongs to
 * in a pass that renders several views at once (bits 24-31; shadow maps,
 * FrameParams below). `rates` holds one byte per
 * edge: 0 while the edge is still to be measured (or too long to dice), else
 * 1 + log2 of the number of micropolygon edges along it (see mp_bound.h). */
typedef struct {
  float corner[8];
  uint patch; /* or, while bound & split opens an instance, a node of its tree (MP_NODE_REF; mp_instance.h) */
  uint info;
  uint rates;
  uint instance; /* the DeviceInstance placing `patch`, or MP_NO_INSTANCE (mp_instance.h) */
} SubPatch;

#define MP_NO_INSTANCE 0xffffffffu

#define MP_EDGE_CODE(rates, e) (((rates) >> (8u * (uint)(e))) & 0xffu)
#define MP_CODE_RATE(code) (1u << ((code) - 1u))

#define MP_INFO_DEPTH(info) ((info) & 0xffu)
#define MP_INFO_NU(info) (((info) >> 8) & 0xffu)
#define MP_INFO_NV(info) (((info) >> 16) & 0xffu)
#define MP_INFO_VIEW(info) ((info) >> 24)
#define MP_MAKE_INFO(depth, nu, nv) ((uint)(depth) | ((uint)(nu) << 8) | ((uint)(nv) << 16))
#define MP_INFO_VIEW_BITS 0xff000000u
/* A diceable sub-patch's info: its depth and view, and the grid size of its
 * bound & split decision word (mp_bound.h). */
#define MP_DICED_INFO(info, decision) (((info) & (0xffu | MP_INFO_VIEW_BITS)) | ((decision) & 0xffff00u))
/* Views one pass renders at most (the 8 bits of MP_INFO_VIEW). */
#define MP_MAX_PASS_VIEWS 256

/* Largest grid the dicer accepts (micropolygons per side). */
#define MP_MAX_GRID 32

/* What a view's samples are for (FrameParams.view_kind). */
#define MP_VIEW_CAMERA 0 /* the image: color, depth and passes */
#define MP_VIEW_SHADOW 1 /* a light's shadow map: depth only, into its pages */

/* Per-view constants, passed by value to every kernel (the camera's), or as
 * an array indexed by MP_INFO_VIEW in passes that render several views at
 * once (shadow maps). Patches live in the camera's space, right-handed
 * looking down -Z; a view other than the camera's first moves points into
 * its own space by `view` (has_view). There d = -z is the depth in front
 * of the eye. Raster position: rx = ax * x / d + bx, ry = ay * y / d + by
 * (perspective), with d replaced by 1 for orthographic views. Raster y
 * points down in the camera's view. */
typedef struct {
  float ax, bx, ay, by;
  int ortho;
  int width, height;        /* pixels of the sample buffer (crop region) */
  int spp_x, spp_y;         /* stratified samples per pixel */
  float clip_near, clip_far;
  float micropoly_edge;     /* sqrt(shading rate): target edge length, pixels */
  int max_grid;             /* grid side limit (<= MP_MAX_GRID) */
  int max_depth;            /* split depth limit (eye-split and runaway guard) */
  float ribbon;             /* frustum guard band, pixels */
  float eye_epsilon;        /* bounds nearer than this straddle the eye plane */
  int backface_culling;
  uint seed;
  int crop_x0, crop_y0;     /* crop origin in the whole image: sample patterns follow whole-image pixels */
  int normal_pass;          /* samples keep their normal (the Normal pass is wanted) */
  /* The view (see above). */
  int has_view;             /* 0: the camera's space itself */
  float view[12];           /* camera space -> view space, rows of a rigid 3x4 */
  int view_kind;            /* MP_VIEW_CAMERA or MP_VIEW_SHADOW */
  /* Shadow views (mp_shadow.h): the map's page table, its pages per side,
   * the table slot of its raster's page (0, 0) (a clipmap level's window
   * wraps around its table) and the first byte of its page mask pyramid. */
  uint page_table;
  int page_side;
  int page_origin_x, page_origin_y;
  uint page_mask;
  /* Depth of field (the camera's view only; mp_blur.h): a thin lens of
   * radius lens_radius (scene units, y; x is lens_radius * lens_x_scale, the
   * anamorphic ratio) focused on the plane at depth focus_distance, with
   * aperture_blades sides (0: round) turned by aperture_rotation radians.
   * Sub-patches are diced by their blurred size: the target edge grows to
   * dof_dice_factor times the circle of confusion's diameter where that is
   * larger. lens_radius == 0: a pinhole. */
  float lens_radius;
  float lens_x_scale;
  float focus_distance;
  int aperture_blades;
  float aperture_rotation;
  float dof_dice_factor;
  /* Motion blur (the camera's view only): grid vertices have positions at
   * motion_steps times evenly spread over the shutter; 0: no motion. */
  int motion_steps;
  /* Buckets (native/src/pipeline/frame/buckets.h): the sample buffer holds pixels
   * from (bucket_x0, bucket_y0) of the crop region on. bx and by place the
   * raster at the bucket's origin (for bound & split's culling); the
   * samplers instead place points with the whole crop region's frame_bx and
   * frame_by and subtract the bucket's origin in fixed point, so a point
   * lands on the same sub-pixel position in every bucket as in the whole
   * frame. */
  float frame_bx, frame_by;
  int bucket_x0, bucket_y0;
  /* Sample colors per pixel channel by channel (the tile sampler's layout,
   * for 16-lane loads and stores) or sample by sample (mp_sample.h). */
  int planar_colors;
  /* Held-out samples (Holdout) count as covered in the alpha: an opaque
   * film, whose background is laid behind by alpha, shows none through
   * them. 0 leaves them transparent (Film > Transparent, the CLI). */
  int holdout_covers;
  /* Some material can hold out (its program calls mp_add_holdout): else
   * the resolve skips reading the held-out share. */
  int holdouts;
  /* Texture Coordinate > Window: the whole image's normalised device
   * coordinates of a camera-space point (x, y, -d), 0 to 1 from its
   * bottom-left corner: (ndc_ax x / d + ndc_bx, ndc_ay y / d + ndc_by), d
   * replaced by 1 for orthographic views. Shadow views keep the camera's. */
  float ndc_ax, ndc_bx, ndc_ay, ndc_by;
  /* Image lookups filter over this many micropolygon footprints
   * (RenderSettings::texture_filter_width; mp_tex_image.h). */
  float texture_filter;
  /* Where the view's samples lie, so that bound & split may cull a small
   * bound that holds none (mp_bound.h, mp_bound_misses_samples): the
   * camera's pattern (MP_SAMPLES_PATTERN, mp_raster.h), texel centres
   * (MP_SAMPLES_CENTRES: shadow maps), or not known (0: views whose grids
   * serve more than samples, as the shadow markings' do). */
  int samples;
} FrameParams;
#define MP_SAMPLES_UNKNOWN 0
#define MP_SAMPLES_PATTERN 1
#define MP_SAMPLES_CENTRES 2

/* The camera view's occlusion pyramid (mp_occlusion.h): level 0 has a cell
 * per 2^cell_shift x 2^cell_shift pixels holding the farthest depth of the
 * cell's samples (the float's bits; ~0u where a sample is empty), each next
 * level the farthest of 2 x 2 cells of the last. levels == 0: no culling. */
typedef struct {
  int levels;
  int cell_shift;
  int base_w, base_h; /* cells of level 0 */
  /* Shadow views (mp_page_occluded): where the pages' cells and their
   * farthest depths start in the pyramid buffer. */
  uint page_cells, page_farthest;
} OcclusionParams;
#define MP_OCCLUSION_MAX_LEVELS 16

/* Materials (see scene.h): color.w = model. */
#define MP_MODEL_CONSTANT 0
#define MP_MODEL_MATTE 1
#define MP_MODEL_PLASTIC 2
#define MP_MODEL_PRINCIPLED 3
typedef struct {
  float color[4];
  float opacity[4];         /* rgb, w = average used for stochastic coverage */
  float coeffs[4];          /* ka, kd, ks, roughness */
  float specular[4];        /* specular color (plastic) */
  float emission[4];
  float principled[4];      /* metallic, specular, layered (Blender 4.0 and later), flags: 1 retro_diffuse + 2 multiscatter */
  float program[4];         /* compiled node program index or -1, displaces (1/0), surface program (1/0),
                               program computes the alpha (1/0) */
  uint params[4];           /* its program's node values: first in the scene's parameter buffer, count */
} DeviceMaterial;

/* Per object, for material programs: camera -> object space (rows of a 3x4
 * matrix), object -> camera (rows of a 3x4; displacement vectors use its
 * linear part), the texture space that maps object space onto Generated
 * coordinates: generated = (P - location) / (2 size) + 1/2, and object <->
 * world for nodes that work in world space. */
typedef struct {
  float to_object[12];
  float to_camera[12];
  float texspace_location[4];
  float texspace_size[4];
  float to_world[12];   /* object -> world (rows of a 3x4) */
  float from_world[12]; /* world -> object */
  float color[4];       /* Object Info: the object's colour (RGBA) */
  float info[4];        /* Object Info: pass index, random number, 0, 0 */
} DeviceObject;

/* One surface of a prototype placed by one instance (scene.h Instance;
 * geometry/mp_instance.h): the surface's patches, in its own space, once
 * for all its instances, lie under a tree of boxes whose root is `root`
 * (DevicePatchNode); this record carries
 * them to camera space at the shutter's centre (rows of a 3x4 matrix, and
 * the inverse transpose of its linear part for normals).
 * box: the placed surface's camera-space box over the whole shutter,
 * displacement included; reach: how far (camera axes) its points move away
 * from the centre's during the shutter (its patches' displacement bounds,
 * in their own units, grow their boxes before the transform carries them);
 * flags: MP_PATCH_FLIP_ORIENTATION (a mirroring transform),
 * MP_PATCH_NO_CAMERA and MP_PATCH_NO_SHADOW (the instance's visibility),
 * added to its patches' own; object: its DeviceObject. */
typedef struct {
  float to_camera[12];
  float normal_to_camera[12];
  float box_lo[4];
  float box_hi[4];
  float reach[4]; /* xyz; w unused */
  uint root; /* MP_NODE_REF(node), or its one patch */
  uint object;
  uint flags;
} DeviceInstance;

/* A node of a prototype surface's tree of patches (geometry/mp_instance.h):
 * the box (its own space, displacement included) around the patches below
 * it, and its two children, each a node (MP_NODE_REF) or a patch. Bound &
 * split opens an instance down this tree, so what a view cannot see is
 * culled a subtree at a time, the whole instance first. */
typedef struct {
  float lo[4]; /* xyz; w unused */
  float hi[4];
  uint child[2];
  uint unused[2];
} DevicePatchNode;

#define MP_NODE_BIT 0x80000000u
#define MP_NODE_REF(node) ((uint)(node) | MP_NODE_BIT)
#define MP_IS_NODE(ref) (((ref) & MP_NODE_BIT) != 0u)
#define MP_NODE_INDEX(ref) ((ref) & ~MP_NODE_BIT)

/* A texture image (scene.h Image): its texels are width * height float4
 * (RGBA, rows bottom to top) from `offset` in the texel buffer; srgb = 1
 * when they hold sRGB-encoded colour to decode after filtering. */
typedef struct {
  uint offset;
  uint width;
  uint height;
  uint srgb;
} DeviceImage;

#define MP_LIGHT_AMBIENT 0
#define MP_LIGHT_DISTANT 1
#define MP_LIGHT_POINT 2
#define MP_LIGHT_SPOT 3
#define MP_LIGHT_AREA 4
/* The world's light (world_lighting.h): irradiance as 9 spherical-harmonic
 * coefficients in two consecutive records, the second typed _DATA. */
#define MP_LIGHT_ENVIRONMENT 5
#define MP_LIGHT_ENVIRONMENT_DATA 6
/* Probe shadows a shaded point looks up (kernels/closures/mp_shading.h). */
#define MP_WORLD_PROBE_LOOKUPS 8
/* A distant light with axis_u[3] == MP_WORLD_PROBE gives no light of its
 * own: its shadow map tells how much of the world's light reaches a point
 * from its part of the sky (world_lighting.h). */
#define MP_WORLD_PROBE 1.0f
#define MP_AREA_RECTANGLE 0
#define MP_AREA_ELLIPSE 1

/* Lights in camera space (units: scene.h). */
typedef struct {
  float color[4];           /* rgb * intensity, w = type */
  float position[4];
  float direction[4];       /* unit direction the light travels */
  float cone[4];            /* cos(outer), cos(inner), beam distribution, 0 */
  float axis_u[4];          /* area: half extent along u, w = shape */
  float axis_v[4];          /* area: half extent along v */
} DeviceLight;

/* Shadow maps of a light (mp_shadow.h), one record per light in the
 * light's order; kind MP_SHADOW_NONE for lights that cast no shadows. */
#define MP_SHADOW_NONE 0u
#define MP_SHADOW_SUN 1u  /* clipmap levels along the light */
#define MP_SHADOW_CUBE 2u /* six perspective faces around the light, with mips */
/* The light's shape, for soft shadows. */
#define MP_SHADOW_SHAPE_POINT 0u     /* no size: hard shadows */
#define MP_SHADOW_SHAPE_DISK 1u      /* sun: size[0] = tan(half angle); point and spot: radius, facing the receiver */
#define MP_SHADOW_SHAPE_RECTANGLE 2u /* area: half extents along light-space x, y */
#define MP_SHADOW_SHAPE_ELLIPSE 3u
typedef struct {
  float to_light[12];  /* camera space -> light space (rows of a rigid 3x4) */
  uint kind;
  uint shape;
  float size[2];
  uint page_table;     /* the light's first page-table entry */
  int level0;          /* sun: its finest level's texels are 2^level0 scene units */
  uint levels;         /* sun: clipmap levels (records from level_records) */
  uint level_records;
  int level_bias;      /* levels (mips) coarser than the footprint asks for: a short budget */
  float z_top;         /* sun: light-space z from which view depth counts down */
  float cone_cos;      /* spot: cosine of the cone's half angle (receivers outside get no light); else -2 */
  uint one_sided;      /* area: only receivers on the light's -z side get light */
} DeviceShadow;

/* A sun's clipmap level: window-relative light-space x, y = x + offset,
 * texels of `texel` scene units, and the table slot of the window's page
 * (0, 0) (the table wraps around). */
typedef struct {
  float offset[2];
  float texel;
  uint page_table;
  int origin_x, origin_y;
  float pad[2];
} DeviceShadowLevel;

#endif
