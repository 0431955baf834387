#include "scene/points.h"

#include <algorithm>
#include <cmath>

#include "micropoly/error.h"
#include "scene/quadrics.h"

namespace mp {
namespace {

// The shape's unit prototype: found by its name, made on first use.
int unit_prototype(Scene& scene, PointShape shape) {
  const char* name = shape == PointShape::Sphere ? "micropoly:unit point sphere" : "micropoly:unit point disc";
  for (size_t i = 0; i < scene.prototypes.size(); ++i)
    if (scene.prototypes[i].name == name) return int(i);
  BezierPatches set;
  set.name = name;
  set.control_points = shape == PointShape::Sphere
                           ? quadric_patches(QuadricKind::Sphere, {1.0, -1.0, 1.0, 360.0}, kPointArcDegrees)
                           : quadric_patches(QuadricKind::Disk, {0.0, 1.0, 360.0}, kPointArcDegrees);
  // A disc is seen from both sides (its shadow from behind it); a sphere is closed.
  set.double_sided = shape == PointShape::Disc;
  Prototype p;
  p.name = name;
  p.bezier_patches.push_back(std::move(set));
  scene.prototypes.push_back(std::move(p));
  return int(scene.prototypes.size() - 1);
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// A rotation taking +z to `n` (unit), any turn about it.
glm::mat3 facing(const glm::vec3& n) {
  const glm::vec3 helper = std::fabs(n.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  const glm::vec3 x = glm::normalize(glm::cross(helper, n)), y = glm::cross(n, x);
  return glm::mat3(x, y, n);
}

}  // namespace

size_t add_point_cloud(Scene& scene, const PointCloud& cloud, const glm::vec3& eye, bool eye_is_direction) {
  if (cloud.positions.size() != cloud.radii.size())
    throw Error("point cloud '" + cloud.name + "': " + std::to_string(cloud.positions.size()) + " positions but " +
                std::to_string(cloud.radii.size()) + " radii");
  if (!cloud.point_attributes.empty() && cloud.point_attributes.size() != cloud.positions.size())
    throw Error("point cloud '" + cloud.name + "': " + std::to_string(cloud.point_attributes.size()) +
                " points' attributes for " + std::to_string(cloud.positions.size()) + " points");
  for (const std::vector<glm::vec3>& step : cloud.motion_positions)
    if (step.size() != cloud.positions.size())
      throw Error("point cloud '" + cloud.name + "': a motion step has " + std::to_string(step.size()) +
                  " positions for " + std::to_string(cloud.positions.size()) + " points");
  if (!cloud.motion_positions.empty() && !cloud.motion_object_to_world.empty() &&
      cloud.motion_positions.size() != cloud.motion_object_to_world.size())
    throw Error("point cloud '" + cloud.name + "': motion positions and transforms differ in steps");
  const size_t steps = std::max(cloud.motion_positions.size(), cloud.motion_object_to_world.size());
  const int prototype = unit_prototype(scene, cloud.shape);
  // Radii are object-space lengths: the object's scale carries them (its
  // cube root for a disc, which faces the eye in world space).
  const glm::mat3 linear(cloud.object_to_world);
  const float scale = std::cbrt(std::fabs(glm::determinant(linear)));
  size_t skipped = 0;
  scene.instances.reserve(scene.instances.size() + cloud.positions.size());
  for (size_t i = 0; i < cloud.positions.size(); ++i) {
    const glm::vec3 p = cloud.positions[i];
    const float r = cloud.radii[i];
    if (!finite(p) || !(r > 0.0f) || !std::isfinite(r)) {
      ++skipped;
      continue;
    }
    Instance inst;
    inst.prototype = prototype;
    if (cloud.shape == PointShape::Sphere) {
      auto placed = [&](const glm::mat4& object_to_world, const glm::vec3& at) {
        glm::mat4 local(r);
        local[3] = glm::vec4(at, 1.0f);
        return object_to_world * local;
      };
      inst.object_to_world = placed(cloud.object_to_world, p);
      for (size_t k = 0; k < steps; ++k) {
        const glm::vec3 at = cloud.motion_positions.empty() ? p : cloud.motion_positions[k][i];
        inst.motion_object_to_world.push_back(placed(
            cloud.motion_object_to_world.empty() ? cloud.object_to_world : cloud.motion_object_to_world[k],
            finite(at) ? at : p));
      }
    } else {
      const glm::vec3 at = glm::vec3(cloud.object_to_world * glm::vec4(p, 1.0f));
      const glm::vec3 to_eye = eye_is_direction ? eye : eye - at;
      const float d = glm::length(to_eye);
      const glm::mat3 turn = d > 0.0f ? facing(to_eye / d) : glm::mat3(1.0f);
      glm::mat4 world(turn * (r * scale));
      world[3] = glm::vec4(at, 1.0f);
      inst.object_to_world = world;
    }
    inst.material = cloud.material;
    inst.info = cloud.info;
    if (!cloud.point_attributes.empty()) inst.info.attributes = cloud.point_attributes[i];
    inst.visible_camera = cloud.visible_camera;
    inst.cast_shadows = cloud.cast_shadows;
    scene.instances.push_back(std::move(inst));
  }
  return skipped;
}

}  // namespace mp
