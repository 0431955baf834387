/* The scene's device data, named once (in the spirit of Cycles' kernel data
 * arrays). Host and kernels both expand this list:
 *  - the host's SceneBuffers (native/src/pipeline/device_scene/scene_buffers.h)
 *    declares a buffer or a count for each entry, in this order;
 *  - a kernel that reads the scene takes MP_SCENE_PARAMS as its first
 *    parameters, so every such kernel sees the same names at the same
 *    argument indices;
 *  - the host binds them once, by this list (SceneKernel), and again only
 *    when a buffer is replaced; a launch binds its batch and its own few
 *    arguments after them.
 * An entry is BUFFER(element type, name) or VALUE(type, name). Adding scene
 * data is one line here and one upload in scene_buffers.cpp. */
#ifndef MP_SCENE_DATA_H
#define MP_SCENE_DATA_H

#define MP_SCENE_DATA(BUFFER, VALUE)                                                                               \
  BUFFER(const float4, points)             /* MP_PATCH_POINTS per patch (geometry/mp_patch.h) */                  \
  BUFFER(const uint, patch_info)           /* 4 per patch: first point, material, object and flags, ... */        \
  BUFFER(const uint, patch_edges)          /* MP_EDGE_REFS per patch */                                            \
  BUFFER(const float4, edge_curves)        /* MP_CURVE_FLOAT4S per shared edge curve */                            \
  BUFFER(const DeviceMaterial, materials)                                                                          \
  BUFFER(const DeviceObject, objects)                                                                              \
  BUFFER(const float4, object_attributes)  /* object_attribute_count per object (Attribute: Object, Instancer) */ \
  BUFFER(const DeviceLight, lights)        /* the scene's and its world's, camera space */                        \
  BUFFER(const float4, patch_uvs)          /* 2 per patch and UV layer */                                          \
  BUFFER(const float4, patch_normals)      /* 4 per patch: smooth shading normals at its corners */               \
  BUFFER(const float4, patch_bounds)       /* 2 per patch: camera-space box, displacement included */             \
  BUFFER(const DeviceImage, images)                                                                                \
  BUFFER(const float4, texels)                                                                                     \
  BUFFER(const float, node_params)         /* material programs' parameters (material_program.cl) */             \
  BUFFER(const float4, world_glossy)       /* the world's glossy maps (closures/mp_world.h), or one zero texel */ \
  BUFFER(const float4, motion_points)      /* points at each motion step, or one float4 without motion */         \
  BUFFER(const float4, motion_curves)      /* edge curves at each motion step, likewise */                        \
  BUFFER(const DeviceInstance, instances)  /* prototype surfaces placed by instances (geometry/mp_instance.h) */ \
  BUFFER(const DevicePatchNode, patch_nodes) /* prototype surfaces' trees of patches (mp_types.h) */            \
  BUFFER(const float4, instance_motion)    /* 3 rows per instance at each motion step, or one float4 */           \
  BUFFER(const uint, refract_roots)        /* refraction proxies (geometry/mp_refract_trace.h) */                 \
  BUFFER(const float4, refract_nodes)                                                                              \
  BUFFER(const float4, refract_tris)                                                                               \
  VALUE(uint, world_params_at)             /* the world program's first parameter in node_params */               \
  VALUE(uint, motion_steps)                                                                                        \
  VALUE(uint, point_count)                 /* float4s of one motion step in motion_points */                      \
  VALUE(uint, curve_count)                 /* float4s of one motion step in motion_curves */                      \
  VALUE(uint, patch_count)                 /* patches placed on their own (instances' roots follow them) */       \
  VALUE(uint, root_count)                  /* patch_count + instance_count: roots of one view */                  \
  VALUE(uint, instance_count)                                                                                      \
  VALUE(uint, light_count)                                                                                         \
  VALUE(uint, object_attribute_count)                                                                              \
  VALUE(uint, uv_layers)                                                                                           \
  VALUE(uint, image_count)

#ifdef __OPENCL_VERSION__
#define MP_SCENE_PARAM_BUFFER(type, name) __global type* name,
#define MP_SCENE_PARAM_VALUE(type, name) type name,
/* A kernel's first parameters, ending in a comma: `kernel(MP_SCENE_PARAMS uint count, ...)`. */
#define MP_SCENE_PARAMS MP_SCENE_DATA(MP_SCENE_PARAM_BUFFER, MP_SCENE_PARAM_VALUE)
#endif

#endif
