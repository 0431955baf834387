// Instances made real (scene.h): the reference an instanced scene renders like.
#include <algorithm>
#include <string>
#include <utility>

#include "micropoly/scene.h"
#include "scene/orientation.h"

namespace mp {

void reverse_faces(Mesh& mesh, size_t first_face, size_t first_index) {
  size_t offset = first_index;
  for (size_t f = first_face; f < mesh.face_vertex_counts.size(); ++f) {
    const size_t n = static_cast<size_t>(mesh.face_vertex_counts[f]);
    const auto flip = [&](auto& corners) {
      std::reverse(corners.begin() + static_cast<long>(offset), corners.begin() + static_cast<long>(offset + n));
    };
    flip(mesh.face_vertex_indices);
    for (auto& layer : mesh.uv_layers) flip(layer);  // UVs belong to their corners
    if (!mesh.corner_normals.empty()) flip(mesh.corner_normals);
    offset += n;
  }
}

void mirror_patches_u(BezierPatches& set, size_t first_patch) {
  // A ribbon has no sides to swap: it turns to face each view, and its
  // rows are points, not a net (MP_PATCH_CURVE).
  if (set.ribbons) return;
  std::vector<glm::vec3>& cps = set.control_points;
  for (size_t p = 16 * first_patch; p + 16 <= cps.size(); p += 16)
    for (size_t j = 0; j < 4; ++j) {
      std::swap(cps[p + 4 * j + 0], cps[p + 4 * j + 3]);
      std::swap(cps[p + 4 * j + 1], cps[p + 4 * j + 2]);
    }
  // Corners (0,0), (1,0), (1,1), (0,1): u = 0 and u = 1 trade places.
  for (std::vector<glm::vec2>& layer : set.uv_layers)
    for (size_t c = 4 * first_patch; c + 4 <= layer.size(); c += 4) {
      std::swap(layer[c + 0], layer[c + 1]);
      std::swap(layer[c + 2], layer[c + 3]);
    }
}

namespace {

// A prototype surface placed as `inst` says (Instance in scene.h).
template <typename Surface>
void place(Surface& s, const Instance& inst, const std::string& prototype, size_t index) {
  s.name = !inst.name.empty() ? inst.name : prototype + "/" + s.name + "#" + std::to_string(index);
  s.object_to_world = inst.object_to_world * s.object_to_world;
  if (inst.material >= 0) s.material = inst.material;
  if (inst.double_sided >= 0) s.double_sided = inst.double_sided == 1;
  s.visible_camera = s.visible_camera && inst.visible_camera;
  s.cast_shadows = s.cast_shadows && inst.cast_shadows;
  s.info = inst.info;
}

}  // namespace

Scene with_instances_made_real(const Scene& scene) {
  Scene out = scene;
  out.prototypes.clear();
  out.instances.clear();
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const Prototype& proto = scene.prototypes.at(size_t(inst.prototype));
    for (const Mesh& m : proto.meshes) {
      Mesh copy = m;
      place(copy, inst, proto.name, i);
      for (const glm::mat4& t : inst.motion_object_to_world) copy.motion_object_to_world.push_back(t * m.object_to_world);
      if (inst.reverse_orientation) reverse_faces(copy);
      out.meshes.push_back(std::move(copy));
    }
    for (const BezierPatches& b : proto.bezier_patches) {
      BezierPatches copy = b;
      place(copy, inst, proto.name, i);
      if (inst.reverse_orientation) mirror_patches_u(copy);
      out.bezier_patches.push_back(std::move(copy));
    }
  }
  return out;
}

}  // namespace mp
