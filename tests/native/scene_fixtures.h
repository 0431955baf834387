// Small scenes built in code for the native tests.
#pragma once

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/scene.h"
#include "micropoly/settings_util.h"

namespace mp::test {

// Camera at `eye` looking at `target` (Blender-style camera space, -Z forward).
inline Camera look_at(glm::vec3 eye, glm::vec3 target, float fov_degrees = 45.0f) {
  Camera c;
  c.world_to_camera = glm::lookAt(eye, target, glm::vec3(0, 1, 0));
  c.fov_degrees = fov_degrees;
  c.clip_near = 0.01f;
  c.clip_far = 1000.0f;
  return c;
}

inline Scene base_scene(int width, int height, int spp) {
  Scene s;
  s.settings.width = width;
  s.settings.height = height;
  set_samples_per_pixel(s.settings, spp);
  s.settings.filter = PixelFilter::Box;
  s.settings.filter_width = 1.0f;
  Material m;
  m.model = Material::Model::Matte;
  m.color = glm::vec3(0.8f);
  s.materials.push_back(m);
  Light ambient;
  ambient.type = Light::Type::Ambient;
  ambient.intensity = 0.2f;
  s.lights.push_back(ambient);
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(-0.3f, -0.5f, -1.0f));
  s.lights.push_back(sun);
  return s;
}

inline Mesh polygon(const std::vector<glm::vec3>& points) {
  Mesh m;
  m.name = "polygon";
  m.points = points;
  m.face_vertex_counts = {static_cast<int>(points.size())};
  for (int i = 0; i < static_cast<int>(points.size()); ++i) m.face_vertex_indices.push_back(i);
  return m;
}

// An n x n grid of quads over [-size, size]^2 in the plane z = 0.
inline Mesh grid_mesh(int n, float size, SubdivScheme scheme) {
  Mesh m;
  m.name = "grid";
  m.scheme = scheme;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      m.points.push_back(glm::vec3(-size + 2 * size * i / n, -size + 2 * size * j / n, 0.0f));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int v = j * (n + 1) + i;
      m.face_vertex_counts.push_back(4);
      m.face_vertex_indices.insert(m.face_vertex_indices.end(), {v, v + 1, v + n + 2, v + n + 1});
    }
  return m;
}

// A unit cube centred at the origin (8 valence-3 extraordinary vertices).
inline Mesh cube_mesh(SubdivScheme scheme) {
  Mesh m;
  m.name = "cube";
  m.scheme = scheme;
  m.points = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
  m.face_vertex_counts = {4, 4, 4, 4, 4, 4};
  m.face_vertex_indices = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3};
  return m;
}

}  // namespace mp::test
