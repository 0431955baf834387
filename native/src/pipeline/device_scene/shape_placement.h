// Placing a surface's object-space patches (patch_cache.h) into the scene's
// device patches, and its object record: shared by the surfaces placed on
// their own (scene_buffers.cpp) and the prototypes instances place
// (instance_placement.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "micropoly/scene.h"
#include "core/mp_types.h"
#include "subdiv/patch_buffer.h"

namespace mp {

// Camera <-> object transforms, texture space (the points' box where the
// size is zero) and Object Info of one surface.
DeviceObject to_device_object(const glm::mat4& to_camera, const glm::mat4& to_world, glm::vec3 texspace_location,
                              glm::vec3 texspace_size, const std::vector<glm::vec3>& points, const ObjectInfo& info);
// Longest a unit object-space vector can become through `m`.
float max_scale(const glm::mat4& m);
// Appends a shape's control points and edge curves carried by `to_camera`.
void place_positions(const PatchBuffer& shape, const glm::mat4& to_camera, std::vector<glm::vec4>& points,
                     std::vector<glm::vec4>& curves);
// Appends a shape as object `object` (mesh or set: the surface it is).
void place_shape(const PatchBuffer& shape, const glm::mat4& to_camera, const Mesh* mesh, const BezierPatches* set,
                 uint32_t object, const Scene& scene, PatchBuffer& out);

}  // namespace mp
