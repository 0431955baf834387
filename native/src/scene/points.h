// Point clouds as instances of one unit prototype per shape: Blender's point
// clouds as spheres (as Cycles draws them), RIB Points as discs facing the
// camera (as RenderMan draws them). Each point is one Scene Instance whose
// transform places the unit shape at the point with the point's radius, so a
// cloud costs one prototype's patches plus one instance per point, and goes
// through instancing's culling of whole instances before their patches.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "micropoly/scene.h"

namespace mp {

enum class PointShape { Sphere, Disc };

struct PointCloud {
  std::string name;
  PointShape shape = PointShape::Sphere;
  std::vector<glm::vec3> positions;  // object space
  std::vector<float> radii;          // object space, one per point
  glm::mat4 object_to_world{1.0f};
  int material = 0;
  ObjectInfo info;  // the cloud's; every point reads it
  // Each point's own Attribute values (ObjectInfo::attributes), or empty:
  // every point reads info.attributes.
  std::vector<std::vector<glm::vec4>> point_attributes;
  // Motion blur (Scene::motion_steps): the positions and the transform at
  // each step, or empty where they do not move; each point's instance
  // moves with them (spheres only: discs face the camera at the centre).
  std::vector<std::vector<glm::vec3>> motion_positions;
  std::vector<glm::mat4> motion_object_to_world;
  bool visible_camera = true;
  bool cast_shadows = true;
};

// Arcs of the unit shapes: a quarter turn each (8 patches for the sphere, 4
// for the disc; radial error 2.7e-4 of the radius per arc, rib_quadrics' bound).
constexpr double kPointArcDegrees = 90.0;

// Appends the cloud's points as instances of the shape's unit prototype
// (made at the first cloud of that shape and shared by all). Discs face the
// camera: their normal points from the point to `eye` (world space), or
// along `eye` itself where `eye_is_direction` (an orthographic camera).
// Points whose position or radius is not finite, or whose radius is not
// positive, are skipped; returns how many were. Throws mp::Error when the
// positions and radii differ in number.
size_t add_point_cloud(Scene& scene, const PointCloud& cloud, const glm::vec3& eye = glm::vec3(0.0f),
                       bool eye_is_direction = false);

}  // namespace mp
