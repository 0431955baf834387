/* A material program: one material node tree, translated to OpenCL C by the
 * add-on (mp_node_displacement and mp_node_surface, inserted below by the
 * host), built into its own program so that identical trees share one build
 * and a changed tree rebuilds only itself. Its kernels run over a whole
 * batch of diced grids and touch only the vertices of the materials that use
 * this program (DeviceMaterial.program[0]). Lighting is not here: the
 * closures a tree makes are recorded (mp_surface_record.h) and lit by the
 * light program, built once for every tree. */
/* Tells the headers they build a material program (mp_bsdf.h). */
#define MP_MATERIAL_PROGRAM 1
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_grid.h"
#include "materials/mp_node_lib.h"
#include "textures/mp_tex_image.h"
#include "core/mp_scene_data.h"
#include "materials/mp_surface_record.h"

/* Half-thickness of a texture space with no extent along an axis: Blender
 * raises a zero size to 1e-5 (the margin covers its float rounding). */
#define MP_FLAT_TEXSPACE 1.5e-5f

/* @MATERIAL_PROGRAM_SOURCE@ */

inline float mp_row3(__global const float* m, int r, float3 v, float w) {
  return m[4 * r] * v.x + m[4 * r + 1] * v.y + m[4 * r + 2] * v.z + m[4 * r + 3] * w;
}

/* Object -> camera for a direction; camera -> object for a normal uses the
 * transpose of the same linear part (the inverse transpose of its inverse). */
inline float3 mp_object_dir_to_camera(__global const DeviceObject* o, float3 d) {
  return (float3)(mp_row3(o->to_camera, 0, d, 0.0f), mp_row3(o->to_camera, 1, d, 0.0f), mp_row3(o->to_camera, 2, d, 0.0f));
}
inline float3 mp_camera_normal_to_object(__global const DeviceObject* o, float3 n) {
  __global const float* m = o->to_camera;
  float3 r = (float3)(m[0] * n.x + m[4] * n.y + m[8] * n.z, m[1] * n.x + m[5] * n.y + m[9] * n.z,
                      m[2] * n.x + m[6] * n.y + m[10] * n.z);
  float l = length(r);
  return l > 0.0f ? r / l : (float3)(0.0f, 0.0f, 1.0f);
}

/* What every material program kernel reads besides the grid: the patches'
 * edges and UVs, and the texture images. */
typedef struct {
  __global const uint* edges;
  __global const float4* uvs;
  uint uv_layers;
  __global const DeviceImage* images;
  uint image_count;
  __global const float4* texels;
  __global const float* params; /* the node values of the material (or world) being evaluated */
  __global const DeviceObject* objects;
  __global const float4* object_attributes; /* object_attribute_count per object (mp_scene_data.h) */
  uint object_attribute_count;
} MpProgramInputs;

inline MpNodeGlobals mp_node_globals(__global const DeviceObject* o, float3 p, float3 n, const MpProgramInputs* in,
                                     uint patch, float2 uv, const FrameParams* f) {
  MpNodeGlobals g;
  int ortho = f->ortho;
  /* The view direction: camera -> object -> world. */
  float3 v = ortho ? (float3)(0.0f, 0.0f, 1.0f) : normalize(-p);
  float3 vo = (float3)(mp_row3(o->to_object, 0, v, 0.0f), mp_row3(o->to_object, 1, v, 0.0f), mp_row3(o->to_object, 2, v, 0.0f));
  float3 vw = (float3)(mp_row3(o->to_world, 0, vo, 0.0f), mp_row3(o->to_world, 1, vo, 0.0f), mp_row3(o->to_world, 2, vo, 0.0f));
  float vl = length(vw);
  g.I = vl > 0.0f ? vw / vl : (float3)(0.0f, 0.0f, 1.0f);
  g.ray_length = ortho ? -p.z : length(p);
  g.shadow_ray = 0;
  g.camera_ray = 1;
  g.backfacing = dot(n, v) < 0.0f;
  g.fibre = (float3)(0.0f);
  g.fibre_radius = 0.0f;
  g.P = (float3)(mp_row3(o->to_object, 0, p, 1.0f), mp_row3(o->to_object, 1, p, 1.0f), mp_row3(o->to_object, 2, p, 1.0f));
  g.N = mp_camera_normal_to_object(o, n);
  g.object = o;
  g.attributes = in->object_attributes + (ulong)(o - in->objects) * in->object_attribute_count;
  g.attribute_count = in->object_attribute_count;
  g.Nw = mp_object_normal_to_world(&g, g.N);
  g.camera = (float3)(p.x, p.y, -p.z);
  float d = ortho ? 1.0f : -p.z;
  d = d != 0.0f ? d : 1e-30f;
  g.window = (float3)(f->ndc_ax * p.x / d + f->ndc_bx, f->ndc_ay * p.y / d + f->ndc_by, 0.0f);
  float3 loc = (float3)(o->texspace_location[0], o->texspace_location[1], o->texspace_location[2]);
  float3 size = (float3)(o->texspace_size[0], o->texspace_size[1], o->texspace_size[2]);
  float3 rel = g.P - loc;
  /* Along an axis the mesh does not extend (a plane, a card: Blender keeps
   * its texture space 1e-5 thick there), the coordinate is the centre, as
   * Cycles reads it from the mesh's own flat coordinates. Positions brought
   * back from camera space carry round-off thousands of times that
   * thickness, which would scatter a texture's cells across the surface. */
  g.generated = (float3)(size.x > MP_FLAT_TEXSPACE ? rel.x / (2.0f * size.x) : 0.0f,
                         size.y > MP_FLAT_TEXSPACE ? rel.y / (2.0f * size.y) : 0.0f,
                         size.z > MP_FLAT_TEXSPACE ? rel.z / (2.0f * size.z) : 0.0f) + (float3)(0.5f, 0.5f, 0.5f);
  for (uint k = 0; k < MP_NODE_USES_UV_LAYERS; ++k) {
    float2 t = k < in->uv_layers ? mp_patch_uv(in->uvs, in->uv_layers, in->edges, patch, k, uv.x, uv.y) : (float2)(0.0f);
    g.uv[k] = (float3)(t.x, t.y, 0.0f);
  }
  g.images = in->images;
  g.image_count = in->image_count;
  g.texels = in->texels;
  g.params = in->params;
  g.dx = 0;
  g.dy = 0;
  g.footprint = f->texture_filter;
  return g;
}

/* Globals moved fractions tx and ty of the way from g towards the next grid
 * vertices x and y: positions and coordinates move, the normal stays, as
 * when Cycles offsets a shading point by a fraction of its differentials
 * for bump evaluation. */
inline MpNodeGlobals mp_node_globals_step(const MpNodeGlobals* g, const MpNodeGlobals* x, const MpNodeGlobals* y,
                                          float tx, float ty) {
  MpNodeGlobals r = *g;
  r.P = g->P + tx * (x->P - g->P) + ty * (y->P - g->P);
  r.generated = g->generated + tx * (x->generated - g->generated) + ty * (y->generated - g->generated);
  r.camera = g->camera + tx * (x->camera - g->camera) + ty * (y->camera - g->camera);
  r.window = g->window + tx * (x->window - g->window) + ty * (y->window - g->window);
  for (uint k = 0; k < MP_NODE_USES_UV_LAYERS; ++k) r.uv[k] = g->uv[k] + tx * (x->uv[k] - g->uv[k]) + ty * (y->uv[k] - g->uv[k]);
  r.dx = 0;
  r.dy = 0;
  return r;
}

/* The differences nodes take (g.dx and g.dy, MP_NEIGHBOUR_STEP of the way
 * to the next grid vertices nx and ny); with MP_NODE_NEIGHBOURS_OF_NEIGHBOURS
 * (a Bump's height reads a filtered image), those points get theirs too, so
 * the image is filtered alike at every point the height is differenced
 * over. The caller's storage `at` holds the five points. */
#define MP_WITH_NEIGHBOURS(g, nx, ny, at)                                                            \
  do {                                                                                             \
    (at)[0] = mp_node_globals_step(&(g), &(nx), &(ny), MP_NEIGHBOUR_STEP, 0.0f);                   \
    (at)[1] = mp_node_globals_step(&(g), &(nx), &(ny), 0.0f, MP_NEIGHBOUR_STEP);                   \
    MP_NEIGHBOURS_OF_NEIGHBOURS(g, nx, ny, at)                                                     \
    (g).dx = &(at)[0];                                                                             \
    (g).dy = &(at)[1];                                                                             \
  } while (0)
#ifdef MP_NODE_NEIGHBOURS_OF_NEIGHBOURS
#define MP_NEIGHBOUR_POINTS 5
#define MP_NEIGHBOURS_OF_NEIGHBOURS(g, nx, ny, at)                                                 \
  (at)[2] = mp_node_globals_step(&(g), &(nx), &(ny), 2.0f * MP_NEIGHBOUR_STEP, 0.0f);              \
  (at)[3] = mp_node_globals_step(&(g), &(nx), &(ny), MP_NEIGHBOUR_STEP, MP_NEIGHBOUR_STEP);        \
  (at)[4] = mp_node_globals_step(&(g), &(nx), &(ny), 0.0f, 2.0f * MP_NEIGHBOUR_STEP);              \
  (at)[0].dx = &(at)[2], (at)[0].dy = &(at)[3], (at)[1].dx = &(at)[3], (at)[1].dy = &(at)[4];
#else
#define MP_NEIGHBOUR_POINTS 2
#define MP_NEIGHBOURS_OF_NEIGHBOURS(g, nx, ny, at)
#endif

/* Object -> camera for a normal: the transpose of camera -> object's linear part. */
inline float3 mp_object_normal_to_camera(__global const DeviceObject* o, float3 n) {
  __global const float* m = o->to_object;
  float3 r = (float3)(m[0] * n.x + m[4] * n.y + m[8] * n.z, m[1] * n.x + m[5] * n.y + m[9] * n.z,
                      m[2] * n.x + m[6] * n.y + m[10] * n.z);
  float l = length(r);
  return l > 0.0f ? r / l : n;
}

/* The vertex this work-item handles, if its material uses this program,
 * with its (u, v) on the patch. */
inline int mp_program_vertex(uint gid, uint count, __global const uint* vertex_offsets, FrameParams f,
                             __global const SubPatch* diceable, __global const uint* patch_info,
                             __global const DeviceInstance* instances, __global const DeviceMaterial* materials,
                             int program, SubPatch* sp, uint* material, uint* object, float2* uv, uint* i, uint* j,
                             ulong* index) {
  if (!mp_grid_vertex(gid, count, vertex_offsets, f.max_grid, diceable, sp, i, j, uv, index)) return 0;
  *material = patch_info[4 * (ulong)sp->patch + 1];
  *object = MP_PATCH_OBJECT(mp_placed_flags(patch_info, instances, sp->patch, sp->instance));
  return (int)materials[*material].program[0] == program;
}
/* What node programs read of the scene (mp_node_lib.h), from MP_SCENE_PARAMS. */
#define MP_PROGRAM_INPUTS \
  {patch_edges, patch_uvs, uv_layers, images, image_count, texels, node_params, objects, object_attributes, \
   object_attribute_count}

/* A tree builds either as a material's program (displace and shade) or as
 * the world's (its radiance baked and behind the frame): the host defines
 * MP_WORLD_PROGRAM for the world's, and each builds only its own kernels. */
#ifndef MP_WORLD_PROGRAM
/* Moves each vertex by the program's displacement vector (object space). */
__kernel void displace_grids(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, FrameParams f,
                             int program, __global float4* grid_p, __global const float4* grid_n,
                             __global const uint* vertex_offsets) {
  uint gid = get_global_id(0), material, object, i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  if (!mp_program_vertex(gid, count, vertex_offsets, f, diceable, patch_info, instances, materials, program, &sp, &material,
                         &object, &uv, &i, &j, &index))
    return;
  if (!(materials[material].program[1] > 0.0f)) return;
  __global const DeviceObject* o = objects + object;
  float3 p = grid_p[index].xyz;
  MpProgramInputs in = MP_PROGRAM_INPUTS;
  in.params += materials[material].params[0];
  MpNodeGlobals g = mp_node_globals(o, p, grid_n[index].xyz, &in, sp.patch, uv, &f);
  g.camera_ray = 0; /* Cycles displaces with no ray */
  /* No neighbours (g.dx null): an image the displacement reads is read at
   * level 0, however small the micropolygons, because a footprint differs
   * between the grids on either side of a shared edge, and a displacement
   * that depended on it would open cracks there (docs/pipeline.md). */
  float3 d = mp_node_displacement(&g);
  if (!(isfinite(d.x) && isfinite(d.y) && isfinite(d.z))) return;
  grid_p[index] = (float4)(p + mp_object_dir_to_camera(o, d), 1.0f);
}

/* Evaluates the node tree at each vertex: only its alpha for a shadow view
 * (alpha_only), else its closures, recorded in this launch's range of the
 * record pool (its global offset is the pool's first vertex) for the light
 * program to light (light_program.cl). */
__kernel void shade_program_grids(MP_SCENE_PARAMS __global const SubPatch* diceable, uint count, FrameParams f,
                                  int program, __global const float4* grid_p, __global float4* grid_n,
                                  __global float4* grid_c, __global const uint* vertex_offsets, uint alpha_only,
                                  __global const uchar* visible, __global float4* records, uint record_stride) {
  uint gid = get_global_id(0), material, object, i, j;
  SubPatch sp;
  float2 uv;
  ulong index;
  /* Every record of the range says whether it holds a surface; the light
   * program reads no other. */
  const uint k = gid - (uint)get_global_offset(0);
  if (!alpha_only) mp_record_skip(records, record_stride, k);
  if (!mp_program_vertex(gid, count, vertex_offsets, f, diceable, patch_info, instances, materials, program, &sp, &material,
                         &object, &uv, &i, &j, &index))
    return;
  if (mp_grid_unseen(visible, index, f.max_grid, materials, patch_info, sp.patch)) return;
  DeviceMaterial m = materials[material];
  if (!(m.program[2] > 0.0f)) return;
  /* A shadow view needs only the alpha, and only of programs that compute it. */
  if (alpha_only && !(m.program[3] > 0.0f)) return;
  float3 p = grid_p[index].xyz, n = grid_n[index].xyz;
  MpProgramInputs in = MP_PROGRAM_INPUTS;
  in.params += m.params[0];
  __global const DeviceObject* o = objects + object;
  MpNodeGlobals g = mp_node_globals(o, p, n, &in, sp.patch, uv, &f);
  /* Smooth shading normals already face the viewer (shade.cl); w = 2 says
   * the surface itself faced away. */
  if (grid_n[index].w > 0.5f) g.backfacing = grid_n[index].w > 1.5f;
  g.shadow_ray = alpha_only != 0;
  g.camera_ray = alpha_only == 0;
#ifdef MP_NODE_USES_HAIR
  {
    /* Hair closures light a fibre along its tangent: the patch's v, which
     * runs from root to tip on a hair tube (scene/curves.h). */
    MpPlacement place = mp_instance_placement(instances, sp.instance);
    float3 sp_p, dpdu, dpdv;
    mp_surface_point(points, patch_info, patch_edges, edge_curves, sp.patch, uv.x, uv.y, &place, &sp_p, &dpdu, &dpdv);
    float3 t = (float3)(mp_row3(o->to_object, 0, dpdv, 0.0f), mp_row3(o->to_object, 1, dpdv, 0.0f),
                        mp_row3(o->to_object, 2, dpdv, 0.0f));
    float lt = length(t);
    g.fibre = lt > 0.0f && isfinite(lt) ? t / lt : (float3)(0.0f);
    /* A tube's u is a quarter turn, a quarter of the circumference; a
     * ribbon's u spans its width, the diameter. */
    if (patch_info[4 * (ulong)sp.patch + 2] & MP_PATCH_ROUND_U) g.fibre_radius = length(dpdu) * (2.0f / M_PI_F);
    if (patch_info[4 * (ulong)sp.patch] == MP_PATCH_CURVE) g.fibre_radius = 0.5f * length(dpdu);
  }
#endif
  /* The next grid vertex along u and along v (the previous one on the
   * grid's far border): bump nodes difference towards them, and sharp lobes
   * widen by the normal's spread to them. */
  MpGridShape shape = mp_grid_shape(&sp, (uint)f.max_grid);
  uint here = mp_slot(&shape, i, j), sx, sy;
  mp_grid_steps(&shape, i, j, &sx, &sy);
  ulong gx = index - here + sx, gy = index - here + sy;
  /* Past the contour by less than a micropolygon: the side in front. */
  int faced = grid_n[index].w > 0.5f;
  if (!faced && g.backfacing && mp_grid_beside_contour(grid_p, grid_n, index - here, &shape, i, j, f.ortho))
    faced = 1, g.backfacing = 0;
#ifdef MP_NODE_USES_NEIGHBOURS
  /* Bump nodes go MP_NEIGHBOUR_STEP of the way: a small step keeps the
   * difference first-order even where a micropolygon spans much of a
   * texture's feature (grazing views); image lookups scale it back to a
   * whole micropolygon's footprint. */
  uint stride = (uint)f.max_grid + 1u;
  float2 uvx = uv, uvy = uv;
  mp_slot_uv(&sp, &shape, sx % stride, sx / stride, &uvx);
  mp_slot_uv(&sp, &shape, sy % stride, sy / stride, &uvy);
  MpNodeGlobals nx = mp_node_globals(o, grid_p[gx].xyz, grid_n[gx].xyz, &in, sp.patch, uvx, &f);
  MpNodeGlobals ny = mp_node_globals(o, grid_p[gy].xyz, grid_n[gy].xyz, &in, sp.patch, uvy, &f);
  MpNodeGlobals near[MP_NEIGHBOUR_POINTS];
  MP_WITH_NEIGHBOURS(g, nx, ny, near);
#endif
  MpSurface s;
  mp_surface_init(&s, g.N);
  mp_node_surface(&g, &s);
  float alpha = mp_surface_alpha(&s);
  if (alpha_only) {
    grid_c[index].w = alpha;
    return;
  }
  /* Normals and tangents from the program's object space to camera space;
   * the surface's own normal is the grid's, exactly. */
  for (int k = 0; k < s.normals; ++k) {
    float3 nk = s.normal[k];
    int valid = all(isfinite(nk)) && length(nk) > 1e-6f;
    s.normal[k] = k == 0 && s.normal_mode[0] == 0 ? n : valid ? mp_object_normal_to_camera(o, nk) : n;
    if (!valid) s.normal_mode[k] = 0;
  }
  for (int k = 0; k < s.count; ++k)
    if (dot(s.c[k].tangent, s.c[k].tangent) > 0.0f) {
      float3 t = mp_object_dir_to_camera(o, s.c[k].tangent);
      s.c[k].tangent = all(isfinite(t)) ? t : (float3)(0.0f);
    }
  /* The light program lights it (light_program.cl), with the normal's
   * spread across the micropolygon (mp_normal_spread2): the grid's normals,
   * final since shade.cl. */
  /* Bit 1 of the faced word: a ribbon's vertex (MpShadowQuery.ribbon). */
  int ribbon = patch_info[4 * (ulong)sp.patch] == MP_PATCH_CURVE;
  mp_record_store(records, record_stride, k, &s, (uint)index, object, faced | (ribbon << 1), alpha,
                  mp_normal_spread2(n, grid_n[gx].xyz, grid_n[gy].xyz));
}

#else

/* The world's radiance towards world direction d: the world program's
 * Surface emission (a Background node's colour times its strength). World
 * nodes see that direction as their position, normal and Generated
 * coordinate, as in Cycles' world shaders. `camera_ray`: the world seen
 * behind the frame (1) or lighting surfaces (0, Cycles' background light:
 * Light Path's outputs all 0 but Ray Length). `camera` and `window`: the
 * view's direction in Cycles' camera space and its image position, for
 * the world behind the frame (zero in the baked light). */
float3 mp_world_radiance(float3 d, const MpProgramInputs* in, int camera_ray, float3 camera, float3 window) {
  MpNodeGlobals g;
  g.P = d;
  g.N = d;
  g.Nw = d;
  g.generated = d;
  g.camera = camera;
  g.window = window;
  for (uint k = 0; k < MP_NODE_USES_UV_LAYERS; ++k) g.uv[k] = (float3)(0.0f);
  g.object = 0;
  g.attributes = 0;
  g.attribute_count = 0;
  g.images = in->images;
  g.image_count = in->image_count;
  g.texels = in->texels;
  g.params = in->params;
  g.dx = 0;
  g.dy = 0;
  g.footprint = 0.0f;
  g.I = -d;
  g.ray_length = 1e30f;
  g.shadow_ray = 0;
  g.camera_ray = camera_ray;
  g.backfacing = 0;
  g.fibre = (float3)(0.0f);
  g.fibre_radius = 0.0f;
  MpSurface s;
  mp_surface_init(&s, d);
  mp_node_surface(&g, &s);
  float3 e = s.emission;
  return (float3)(isfinite(e.x) ? fmax(e.x, 0.0f) : 0.0f, isfinite(e.y) ? fmax(e.y, 0.0f) : 0.0f,
                  isfinite(e.z) ? fmax(e.z, 0.0f) : 0.0f);
}

/* The world over an equirectangular map (scene.h, World), at each texel's
 * centre, as the light surfaces receive; the world's node values from
 * world_params_at in the parameter buffer. */
__kernel void bake_world(MP_SCENE_PARAMS uint width, uint height, __global float4* out) {
  uint i = get_global_id(0);
  if (i >= width * height) return;
  float u = ((float)(i % width) + 0.5f) / (float)width, v = ((float)(i / width) + 0.5f) / (float)height;
  MpProgramInputs in = MP_PROGRAM_INPUTS;
  in.params += world_params_at;
  /* The light is baked once for every view: no image position (the node
   * compiler warns of these outputs in a world). */
  float3 zero = (float3)(0.0f);
  out[i] = (float4)(mp_world_radiance(mp_env_equirect_direction(u, v), &in, 0, zero, zero), 1.0f);
}

/* The world behind each pixel of the frame (its crop), laid under the
 * resolved image `rgba` in place as an opaque film shows it (colour plus
 * the world times what alpha leaves, alpha 1): the mean of 2 x 2 stratified
 * rays through the pixel, the raster mapping of FrameParams inverted, turned
 * into the world by rows r0..r2 (camera to world). */
__kernel void world_pixels(MP_SCENE_PARAMS FrameParams f, float4 r0, float4 r1, float4 r2, __global float4* rgba) {
  uint i = get_global_id(0);
  if (i >= (uint)f.width * (uint)f.height) return;
  float px = (float)(i % (uint)f.width), py = (float)(i / (uint)f.width);
  MpProgramInputs in = MP_PROGRAM_INPUTS;
  in.params += world_params_at;
  float3 sum = (float3)(0.0f);
  for (int s = 0; s < 4; ++s) {
    /* The ray's point on the image plane at depth 1 (perspective: its
     * direction; orthographic: where it starts, looking down -z). */
    float3 c = (float3)((px + ((float)(s % 2) + 0.5f) * 0.5f - f.bx) / f.ax,
                        (py + ((float)(s / 2) + 0.5f) * 0.5f - f.by) / f.ay, -1.0f);
    float3 d = f.ortho ? (float3)(0.0f, 0.0f, -1.0f) : c;
    /* Texture Coordinate: Camera is the direction in Cycles' +Z-forward
     * camera space, Window the image position, as Cycles gives a camera
     * ray that meets the world. */
    float3 dn = normalize(d);
    float3 window = (float3)(f.ndc_ax * c.x + f.ndc_bx, f.ndc_ay * c.y + f.ndc_by, 0.0f);
    sum += mp_world_radiance((float3)(dot(r0.xyz, d), dot(r1.xyz, d), dot(r2.xyz, d)), &in, 1,
                             (float3)(dn.x, dn.y, -dn.z), window);
  }
  sum *= 0.25f;
  float4 c = rgba[i];
  rgba[i] = (float4)(c.xyz + (1.0f - c.w) * sum, 1.0f);
}
#endif
