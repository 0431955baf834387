// A 64-bit fingerprint of everything in a Scene that the uploaded scene
// buffers (HostSceneData) depend on: geometry, transforms, the camera's
// placement, materials, lights and images. Resolution, samples, shading rate
// and the other settings do not enter, so re-rendering a scene at another
// sample count or size (progressive viewport passes, repeated frames) can
// reuse the buffers already on the device.
#pragma once

#include <cstdint>
#include <vector>

#include "micropoly/scene.h"

namespace mp {

uint64_t scene_fingerprint(const Scene& scene);
// The world's light and background (scene.h, World): its program or map,
// visibility, probe count and, for a program, the images it may read.
uint64_t world_fingerprint(const Scene& scene);

// What the scene's shadow maps' contents depend on besides each light
// (kernels/shadow/mp_shadow.h), split so that a frame can tell which
// surfaces changed (shadow_changes.h): `global`, what every surface's
// shadow depends on (the shutter, and the images that displacing or alpha
// programs may read), then one key per surface (in Scene order): its shape
// and placement in world space, motion, whether it casts shadows, its
// materials' opacity, displacement and alpha programs, and the object info
// those programs may read. Not the camera, and not the lights.
struct ShadowGeometryKeys {
  uint64_t global = 0;
  std::vector<uint64_t> meshes, patch_sets;
  std::vector<uint64_t> instances;  // each instance with its prototype's surfaces
};
ShadowGeometryKeys shadow_geometry_keys(const Scene& scene);
// All of them in one.
uint64_t geometry_fingerprint(const Scene& scene);
uint64_t geometry_fingerprint(const ShadowGeometryKeys& keys);

// What one light's shadow pages depend on besides the surfaces they hold:
// `geometry_key` (ShadowGeometryKeys::global), the light's place, shape and
// size, the settings that dice the shadow views, and (suns) the depth their
// maps count from.
uint64_t shadow_light_key(const Light& light, uint64_t geometry_key, const RenderSettings& settings, float z_top);

// Fingerprints of what a surface's object-space patches depend on (its
// shape, tags and UVs, and the number of UV layers the scene's patches
// carry), but not its name, transform, materials or sidedness: equal meshes
// placed several times (instances, duplicates) share one key.
uint64_t mesh_shape_key(const Mesh& mesh, int uv_layers);
uint64_t patch_set_shape_key(const BezierPatches& set, int uv_layers);

}  // namespace mp
