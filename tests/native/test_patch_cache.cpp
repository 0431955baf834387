// The object-space patch cache (pipeline/device_scene/patch_cache.h): shapes are built
// once and placed per object, and a placed shape equals the patches the
// builders make directly in camera space (OpenSubdiv refinement included).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "pipeline/device_scene/patch_cache.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "geometry/mp_patch.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// Two equal tori (one mirrored, single-sided, with per-face materials), a
// different cube, a polygon grid with UVs and a Bezier patch set.
Scene instanced_scene() {
  Scene s = base_scene(64, 48, 1);
  s.camera = look_at({1.0f, -7.0f, 4.0f}, {0.0f, 0.0f, 0.0f});
  for (int i = 0; i < 4; ++i) {
    Material m;
    m.color = glm::vec3(0.2f * float(i));
    s.materials.push_back(m);
  }
  s.materials[3].program = 0;  // displaced: the bound scales with the object
  s.materials[3].program_displaces = true;
  s.materials[3].displacement_bound = 0.25f;
  s.material_programs.push_back({"p", "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }"});
  Mesh torus = torus_mesh(8, 6, 0.3f, SubdivScheme::CatmullClark);
  torus.crease_vertices = {0, 1};
  torus.crease_sharpness = {2.0f};
  torus.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(-1.5f, 0.0f, 0.0f));
  torus.material = 1;
  s.meshes.push_back(torus);
  Mesh twin = torus;
  twin.name = "twin";
  twin.object_to_world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(1.5f, 0.5f, 0.2f)), 0.7f,
                                                glm::vec3(0.3f, 0.2f, 1.0f)),
                                    glm::vec3(-0.8f, 1.1f, 0.9f));
  twin.double_sided = false;
  twin.face_materials.assign(twin.face_vertex_counts.size(), 2);
  twin.face_materials[5] = 3;
  s.meshes.push_back(twin);
  Mesh cube = cube_mesh(SubdivScheme::CatmullClark);
  cube.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 1.5f, 0.0f));
  s.meshes.push_back(cube);
  Mesh floor = grid_mesh(3, 4.0f, SubdivScheme::None);
  std::vector<glm::vec2> uvs;
  for (int v : floor.face_vertex_indices) uvs.push_back(glm::vec2(floor.points[size_t(v)]) * 0.25f);
  floor.uv_layers = {uvs};
  for (int v : floor.face_vertex_indices)  // smooth-shaded, tilted normals
    floor.corner_normals.push_back(glm::normalize(glm::vec3(floor.points[size_t(v)].x * 0.2f, 0.1f, 1.0f)));
  floor.material = 3;
  floor.object_to_world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -1.0f)), 0.3f,
                                                 glm::vec3(1, 0, 0)),
                                     glm::vec3(1.0f, 2.5f, 1.0f));  // normals need the inverse transpose
  s.meshes.push_back(floor);
  BezierPatches set;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) set.control_points.push_back({i * 0.3f, j * 0.3f, (i % 3 && j % 3) ? 0.4f : 0.0f});
  set.material = 2;
  set.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, -1.0f, 0.5f));
  s.bezier_patches.push_back(set);
  return s;
}

// The patches the builders make for one surface directly in camera space.
PatchBuffer direct(const Scene& s, size_t surface, int uv_layers) {
  PatchBuffer b;
  b.uv_layers = uv_layers;
  if (surface < s.meshes.size()) {
    const Mesh& m = s.meshes[surface];
    const glm::mat4 to_camera = s.camera.world_to_camera * m.object_to_world;
    if (m.scheme == SubdivScheme::CatmullClark)
      append_subdiv_patches(m, to_camera, b);
    else
      append_polygon_patches(m, to_camera, b);
  } else {
    const BezierPatches& set = s.bezier_patches[surface - s.meshes.size()];
    append_bezier_patches(set, s.camera.world_to_camera * set.object_to_world, b);
  }
  share_patch_edges(b, 0);
  return b;
}

TEST(PatchCache, EqualShapesAreBuiltOnceAndKeptAcrossCameraMoves) {
  Scene s = instanced_scene();
  PatchCache cache;
  HostSceneData first = prepare_scene_data(s, &cache);
  EXPECT_EQ(cache.builds(), 4u);  // torus (twice placed), cube, floor, patch set
  EXPECT_EQ(cache.hits(), 1u);
  s.camera = look_at({3.0f, -6.0f, 2.0f}, {0.0f, 0.5f, 0.0f});
  s.meshes[2].object_to_world = glm::mat4(1.0f);  // a moved object is only re-placed
  prepare_scene_data(s, &cache);
  EXPECT_EQ(cache.builds(), 4u);
  EXPECT_EQ(cache.hits(), 6u);
  s.meshes[2].points[0].x += 0.1f;  // an edited shape is rebuilt, alone
  prepare_scene_data(s, &cache);
  EXPECT_EQ(cache.builds(), 5u);
}

TEST(PatchCache, PlacedShapesMatchPatchesBuiltInCameraSpace) {
  const Scene s = instanced_scene();
  PatchCache cache;
  const HostSceneData data = prepare_scene_data(s, &cache);
  const PatchBuffer& placed = data.patches;
  const int layers = placed.uv_layers;
  EXPECT_EQ(layers, 1);
  size_t patch = 0, curve = 0;
  for (size_t surface = 0; surface < s.meshes.size() + s.bezier_patches.size(); ++surface) {
    SCOPED_TRACE("surface " + std::to_string(surface));
    const PatchBuffer d = direct(s, surface, layers);
    ASSERT_LE(patch + d.size(), placed.size());
    ASSERT_LE(curve * MP_CURVE_FLOAT4S + d.curves.size(), placed.curves.size());
    float extent = 0.0f;
    for (const glm::vec4& p : d.points) extent = std::max(extent, glm::length(glm::vec3(p)));
    const float tol = 2e-6f * extent;
    for (size_t p = 0; p < d.size(); ++p) {
      const glm::uvec4 a = placed.info[patch + p], b = d.info[p];
      EXPECT_EQ(a.x, b.x);  // type
      EXPECT_EQ(a.y, b.y);  // material, per face
      EXPECT_EQ(a.z & 0xffu, b.z & 0xffu);  // sidedness, mirroring
      EXPECT_EQ(a.z >> 8, surface);  // object
      EXPECT_EQ(a.w, b.w);
      for (int k = 0; k < MP_PATCH_POINTS; ++k) {
        const glm::vec4 pa = placed.points[(patch + p) * MP_PATCH_POINTS + size_t(k)];
        const glm::vec4 pb = d.points[p * MP_PATCH_POINTS + size_t(k)];
        ASSERT_LE(glm::length(glm::vec3(pa) - glm::vec3(pb)), tol) << "patch " << p << " point " << k;
      }
      // The displacement bound is in camera space: scaled like the object.
      const bool displaced = a.y == 3u;
      EXPECT_EQ(placed.points[(patch + p) * MP_PATCH_POINTS].w > 0.0f, displaced);
      for (int r = 0; r < MP_EDGE_REFS; ++r) {
        const uint32_t ra = placed.edges[(patch + p) * MP_EDGE_REFS + size_t(r)];
        const uint32_t rb = d.edges[p * MP_EDGE_REFS + size_t(r)];
        ASSERT_EQ(ra == MP_NO_CURVE, rb == MP_NO_CURVE);
        if (ra != MP_NO_CURVE) EXPECT_EQ(ra, rb + (uint32_t(curve) << 1));
      }
      for (int c = 0; c < MP_PATCH_NORMALS; ++c) {  // smooth normals: same direction, or both none
        const glm::vec3 na(placed.normals[(patch + p) * MP_PATCH_NORMALS + size_t(c)]);
        const glm::vec3 nb(d.normals[p * MP_PATCH_NORMALS + size_t(c)]);
        ASSERT_EQ(glm::length(na) > 0.0f, glm::length(nb) > 0.0f);
        if (glm::length(nb) > 0.0f) EXPECT_GT(glm::dot(glm::normalize(na), glm::normalize(nb)), 0.99999f);
      }
      for (int k = 0; k < 2 * layers; ++k)
        EXPECT_EQ(placed.uvs[(patch + p) * 2 * size_t(layers) + size_t(k)], d.uvs[p * 2 * size_t(layers) + size_t(k)]);
    }
    // Curves: positions as points, normal cubics as directions (the kernels
    // normalise them and orient them like the patch: compare directions).
    for (size_t c = 0; c < d.curves.size(); c += MP_CURVE_FLOAT4S) {
      const glm::vec4* a = &placed.curves[curve * MP_CURVE_FLOAT4S + c];
      const glm::vec4* b = &d.curves[c];
      for (int k = 0; k < 4; ++k) ASSERT_LE(glm::length(glm::vec3(a[k]) - glm::vec3(b[k])), tol);
      for (float t : {0.0f, 0.3f, 0.5f, 1.0f}) {
        auto eval = [t](const glm::vec4* n) {
          const float s = 1.0f - t;
          return glm::vec3(n[4]) * s * s * s + glm::vec3(n[5]) * 3.0f * s * s * t + glm::vec3(n[6]) * 3.0f * s * t * t +
                 glm::vec3(n[7]) * t * t * t;
        };
        const glm::vec3 na = eval(a), nb = eval(b);
        ASSERT_EQ(glm::length(na) > 0.0f, glm::length(nb) > 0.0f) << "curve " << c / MP_CURVE_FLOAT4S << " t " << t;
        if (glm::length(nb) > 0.0f)
          EXPECT_GT(std::fabs(glm::dot(glm::normalize(na), glm::normalize(nb))), 0.999f)
              << "curve " << c / MP_CURVE_FLOAT4S << " t " << t;
      }
    }
    patch += d.size();
    curve += d.curves.size() / MP_CURVE_FLOAT4S;
  }
  EXPECT_EQ(patch, placed.size());
}

}  // namespace
}  // namespace mp::test
