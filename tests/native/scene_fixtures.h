// Small scenes built in code for the native tests.
#pragma once

#include <cmath>
#include <string>

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

// A torus (ring radius 1, tube radius r) of n x m quads in which every third
// face of one ring is cut into two triangles: the cut's end points become
// extraordinary vertices of valence 5 and the triangles' centres of valence 3.
inline Mesh torus_mesh(int n, int m, float r, SubdivScheme scheme) {
  Mesh t;
  t.name = "torus";
  t.scheme = scheme;
  const float pi = 3.14159265f;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      float a = 2 * pi * i / n, b = 2 * pi * j / m;
      t.points.push_back({(1 + r * std::cos(b)) * std::cos(a), (1 + r * std::cos(b)) * std::sin(a), r * std::sin(b)});
    }
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (j == 0 && i % 3 == 0) {
        t.face_vertex_counts.insert(t.face_vertex_counts.end(), {3, 3});
        t.face_vertex_indices.insert(t.face_vertex_indices.end(), {a, b, c, a, c, d});
      } else {
        t.face_vertex_counts.push_back(4);
        t.face_vertex_indices.insert(t.face_vertex_indices.end(), {a, b, c, d});
      }
    }
  return t;
}

// A UV sphere of radius 1 as flat polygons: quads, with triangle fans at the
// poles (the triangles' patches meet the quads' edges at their midpoints).
inline Mesh uv_sphere_mesh(int rings, int segments) {
  Mesh s;
  s.name = "sphere";
  s.scheme = SubdivScheme::None;
  const float pi = 3.14159265f;
  s.points.push_back({0, 0, -1});
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      float th = pi * r / rings, ph = 2 * pi * k / segments;
      s.points.push_back({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), -std::cos(th)});
    }
  s.points.push_back({0, 0, 1});
  const int top = int(s.points.size()) - 1;
  auto id = [&](int r, int k) { return 1 + (r - 1) * segments + (k + segments) % segments; };
  for (int k = 0; k < segments; ++k) {
    s.face_vertex_counts.push_back(3);
    s.face_vertex_indices.insert(s.face_vertex_indices.end(), {0, id(1, k + 1), id(1, k)});
  }
  for (int r = 1; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      s.face_vertex_counts.push_back(4);
      s.face_vertex_indices.insert(s.face_vertex_indices.end(), {id(r, k), id(r, k + 1), id(r + 1, k + 1), id(r + 1, k)});
    }
  for (int k = 0; k < segments; ++k) {
    s.face_vertex_counts.push_back(3);
    s.face_vertex_indices.insert(s.face_vertex_indices.end(), {top, id(rings - 1, k), id(rings - 1, k + 1)});
  }
  return s;
}

// Adds a material shaded by a program whose surface is a diffuse `colour`
// and then `then` (OpenCL C, with g and s in scope).
inline void add_program_material(Scene& s, const char* name, const char* colour, const std::string& then, bool alpha) {
  s.material_programs.push_back(
      {name, std::string("float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }\n"
                         "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                         " mp_add_diffuse(s, (float3)(") +
                 colour + "), 0, 0.0f); " + then + " }\n"});
  Material m;
  m.model = Material::Model::Principled;
  m.program = int(s.material_programs.size()) - 1;
  m.program_shades = true;
  m.program_alpha = alpha;
  s.materials.push_back(m);
}

}  // namespace mp::test
