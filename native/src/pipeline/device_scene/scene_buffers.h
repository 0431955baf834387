// The scene on the device: patches (camera space), materials and lights.
#pragma once

#include <vector>

#include "cl/cl.h"
#include "micropoly/scene.h"
#include "core/mp_types.h"
#include "core/mp_scene_data.h"
#include "pipeline/device_scene/patch_cache.h"
#include "pipeline/materials/refraction_proxy.h"
#include "pipeline/world/world_lighting.h"
#include "subdiv/patch_buffer.h"

namespace mp {

class DeviceSession;

// Host side: every surface as device patches in camera space, plus materials
// and lights in their device layout. Pure CPU work; no OpenCL involved.
struct HostSceneData {
  // The patches placed on their own (camera space) first, own_patches of
  // them, then the prototypes' (each in its own space, instance_placement.h).
  PatchBuffer patches;
  size_t own_patches = 0;
  // Instances (kernels/geometry/mp_instance.h): one record per prototype
  // surface each instance places, nearest the camera first; the surfaces'
  // trees of patches (patch_tree.h) and the deepest's depth; with motion
  // blur, the records' rows at each step.
  std::vector<DeviceInstance> instances;
  std::vector<DevicePatchNode> patch_nodes;
  int tree_depth = 0;
  std::vector<glm::vec4> instance_motion;
  size_t root_count = 0;       // own_patches + instances.size(): the roots of one view
  uint64_t instanced_patches = 0;  // the patches the instances place, all told
  std::vector<DeviceMaterial> materials;
  std::vector<DeviceLight> lights;
  std::vector<DeviceObject> objects;  // one per surface, in patch order (MP_PATCH_OBJECT)
  // Attribute nodes' per-object values (ObjectInfo::attributes): slots per
  // object (the most any object has), then object after object, zero past
  // an object's own; one zero float4 where no object has any.
  uint32_t object_attribute_count = 0;
  std::vector<glm::vec4> object_attributes;
  void add_object(const DeviceObject& o, const ObjectInfo& info) {
    objects.push_back(o);
    for (uint32_t k = 0; k < object_attribute_count; ++k)
      object_attributes.push_back(k < info.attributes.size() ? info.attributes[k] : glm::vec4(0.0f));
  }
  // Images' offsets count every MIP level (mp_tex_image.h): the device's
  // texel buffer holds device_texels, each image's level 0 at its offset
  // and its other levels after it, built on the device at upload.
  std::vector<DeviceImage> images;
  std::vector<glm::vec4> texels;      // every image's pixels (level 0), one after the other
  size_t device_texels = 0;
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

// The scene's device data: one member per entry of kernels/core/mp_scene_data.h
// (a cl::Buffer per BUFFER, a cl_uint per VALUE), which the kernels declare
// by the same names (MP_SCENE_PARAMS) and SceneKernel binds in its order.
#define MP_HOST_SCENE_BUFFER(type, name) cl::Buffer name;
#define MP_HOST_SCENE_VALUE(type, name) cl_##type name = 0;
struct SceneBuffers {
  MP_SCENE_DATA(MP_HOST_SCENE_BUFFER, MP_HOST_SCENE_VALUE)
  std::vector<glm::vec4> host_patch_bounds;  // patch_bounds on the host (occlusion culling's root order)
  std::vector<glm::vec4> host_instance_bounds;  // 2 per instance: camera-space boxes (the roots' overlap)
  size_t bytes = 0;  // device memory of the scene's geometry and objects (not images or lights)
  int tree_depth = 0;  // HostSceneData's: bound & split's stacks hold a path down it
  uint64_t placed_patches = 0;  // own patches and those the instances place
  // Which upload these buffers are (DeviceSession::next_data_version); every
  // replacement of a buffer takes a new one, so kernels bound to the old
  // buffers bind again (scene_kernel.h).
  uint64_t version = 0;
};
#undef MP_HOST_SCENE_BUFFER
#undef MP_HOST_SCENE_VALUE
SceneBuffers upload_scene_data(DeviceSession& session, const HostSceneData& data);
// The world's glossy maps (kernels/closures/mp_world.h) prefiltered from
// `map` on the device (kernels/stages/world_glossy.cl); zeros for an empty map.
cl::Buffer prefilter_world_glossy(DeviceSession& session, const WorldMap& map);
// Replaces the buffers' world glossy maps with `maps` (prefilter_world_glossy),
// which a renderer keeps while its world stays the same.
void set_world_glossy(DeviceSession& session, const cl::Buffer& maps, SceneBuffers& buffers);
// Replaces the buffers' lights (the scene's and its world's, device_lights).
void upload_lights(DeviceSession& session, const std::vector<Light>& lights,
                   const glm::mat4& world_to_camera, SceneBuffers& buffers);

}  // namespace mp
