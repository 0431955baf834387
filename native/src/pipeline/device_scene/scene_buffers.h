// The scene on the device: patches (camera space), materials and lights.
#pragma once

#include <vector>

#include "cl/cl.h"
#include "micropoly/scene.h"
#include "core/mp_types.h"
#include "pipeline/device_scene/patch_cache.h"
#include "pipeline/materials/refraction_proxy.h"
#include "subdiv/patch_buffer.h"

namespace mp {

class DeviceSession;

// Host side: every surface as device patches in camera space, plus materials
// and lights in their device layout. Pure CPU work; no OpenCL involved.
struct HostSceneData {
  PatchBuffer patches;
  std::vector<DeviceMaterial> materials;
  std::vector<DeviceLight> lights;
  std::vector<DeviceObject> objects;  // one per surface, in patch order (MP_PATCH_OBJECT)
  std::vector<DeviceImage> images;
  std::vector<glm::vec4> texels;      // every image's pixels, one after the other
  // Every material's node values (DeviceMaterial.params gives where each
  // starts), then the world's from world_params_at.
  std::vector<float> params;
  uint32_t world_params_at = 0;
  // Motion blur (Scene::motion_steps): the patches' control points and edge
  // curves in camera space at each step, step after step, each step laid
  // out as patches.points and patches.curves.
  int motion_steps = 0;
  std::vector<glm::vec4> motion_points, motion_curves;
  // Refracting objects' own shapes (refraction_proxy.h).
  RefractionProxies refraction;
};
// Surfaces' object-space patches come from `cache` when given (kept by the
// caller between scenes; patch_cache.h), else they are built for this call.
HostSceneData prepare_scene_data(const Scene& scene, PatchCache* cache = nullptr);
// Lights in their device layout, camera space; an environment light takes
// two records, so it comes last (shadow records follow the lights' order).
std::vector<DeviceLight> device_lights(const std::vector<Light>& lights, const glm::mat4& world_to_camera);

struct SceneBuffers {
  cl::Buffer points;      // float4 x MP_PATCH_POINTS per patch
  cl::Buffer patch_info;  // uint4 per patch
  cl::Buffer patch_edges;  // MP_EDGE_REFS uints per patch (kernels/geometry/mp_patch.h)
  cl::Buffer edge_curves;  // MP_CURVE_FLOAT4S float4 per shared edge curve
  cl::Buffer materials;
  cl::Buffer objects;
  cl::Buffer lights;
  cl::Buffer patch_uvs;   // 2 float4 per patch and UV layer (kernels/geometry/mp_patch.h)
  cl::Buffer patch_normals;  // 4 float4 per patch: smooth shading normals at its corners
  cl::Buffer patch_bounds;   // 2 float4 per patch: camera-space box of its net, displacement included
  std::vector<glm::vec4> host_patch_bounds;  // the same on the host (occlusion culling's root order)
  cl::Buffer images;      // DeviceImage per image
  cl::Buffer texels;      // float4
  cl::Buffer params;      // float: HostSceneData::params
  cl_uint world_params_at = 0;
  cl::Buffer world_glossy;  // float4: the world's glossy maps (kernels/closures/mp_world.h), or one zero texel
  cl::Buffer motion_points, motion_curves;  // HostSceneData's (one float4 when there is no motion)
  cl::Buffer refract_roots, refract_nodes, refract_tris;  // RefractionProxies (kernels/geometry/mp_refract_trace.h)
  cl_uint motion_steps = 0;
  cl_uint point_count = 0, curve_count = 0;  // float4s of one step
  cl_uint patch_count = 0;
  cl_uint light_count = 0;
  cl_uint uv_layers = 0;
  cl_uint image_count = 0;
};
SceneBuffers upload_scene_data(DeviceSession& session, const HostSceneData& data);
// Replaces the world's glossy maps (world_lighting.h, world_glossy_maps).
void upload_world_glossy(DeviceSession& session, const std::vector<glm::vec4>& maps,
                         SceneBuffers& buffers);
// Replaces the buffers' lights (the scene's and its world's, device_lights).
void upload_lights(DeviceSession& session, const std::vector<Light>& lights,
                   const glm::mat4& world_to_camera, SceneBuffers& buffers);

}  // namespace mp
