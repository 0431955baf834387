// Grid vertices just past a subdivision surface's contour (their normals
// already turn away from the camera, their micropolygons still straddle the
// silhouette) shade as the side facing the viewer (mp_grid_beside_contour),
// while a surface seen from behind still shades as its back.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class ContourShadingTest : public SharedRendererTest {};

// An orthographic view down -z of `mesh`, lit only by a distant light
// travelling along `light_dir`.
Scene lit_view(Mesh mesh, glm::vec3 light_dir) {
  Scene s = base_scene(96, 96, 4);
  s.camera = look_at({0, 0, 5}, {0, 0, 0});
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.screen_left = s.camera.screen_bottom = -1.5f;
  s.camera.screen_right = s.camera.screen_top = 1.5f;
  s.meshes.push_back(std::move(mesh));
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(light_dir);
  s.lights = {sun};
  return s;
}

TEST_F(ContourShadingTest, TheRimFacingTheLightStaysLit) {
  // The Catmull-Clark cube's limit surface, turned 30 degrees about y and 20
  // about x so its silhouette runs over curved surface, lit from +x: at the
  // +x silhouette the visible surface faces the light, so in each row the
  // last covered pixel is at least as bright as the surface a few pixels
  // inside, and the partly covered pixel past it (its colour divided by its
  // coverage) as bright as that last one.
  Mesh cube = cube_mesh(SubdivScheme::CatmullClark);
  cube.object_to_world = glm::rotate(glm::rotate(glm::mat4(1.0f), glm::radians(20.0f), glm::vec3(1, 0, 0)),
                                     glm::radians(30.0f), glm::vec3(0, 1, 0));
  const RenderResult r = renderer_->render(lit_view(cube, {-1.0f, 0.0f, 0.0f}));
  auto at = [&](int x, int y, int c) { return r.rgba[4 * (size_t(y) * size_t(r.width) + size_t(x)) + size_t(c)]; };
  int rows = 0, edges = 0, dark = 0;
  float worst = 1.0f;
  for (int y = 24; y < 72; ++y) {
    int last = -1;
    for (int x = 0; x < r.width; ++x)
      if (at(x, y, 3) > 0.999f) last = x;
    if (last < r.width / 2 || last + 1 >= r.width) continue;
    const float inner = at(last - 4, y, 0), rim = at(last, y, 0);
    ASSERT_GT(inner, 0.05f) << "row " << y << ": the surface inside the rim is unlit";
    ++rows;
    float ratio = rim / (0.9f * inner);
    if (at(last + 1, y, 3) >= 0.25f) {
      ++edges;
      ratio = std::min(ratio, at(last + 1, y, 0) / at(last + 1, y, 3) / (0.8f * rim));
    }
    worst = std::min(worst, ratio);
    if (ratio < 1.0f) ++dark;
  }
  ASSERT_GT(rows, 30);
  ASSERT_GT(edges, 20);
  EXPECT_EQ(dark, 0) << "worst ratio to the allowed least " << worst;
}

TEST_F(ContourShadingTest, ASurfaceSeenFromBehindShadesAsItsBack) {
  // An open Catmull-Clark sheet facing away from the camera (its normals
  // point to -z), lit from the camera's side: its back faces the light. No
  // vertex has a contour beside it, so every one is shaded as the back.
  Mesh sheet = grid_mesh(4, 1.0f, SubdivScheme::CatmullClark);
  sheet.object_to_world = glm::rotate(glm::mat4(1.0f), glm::radians(180.0f), glm::vec3(0, 1, 0));
  const RenderResult r = renderer_->render(lit_view(sheet, {0.0f, 0.0f, -1.0f}));
  int covered = 0, dark = 0;
  for (size_t i = 0; i < size_t(r.width) * size_t(r.height); ++i) {
    if (r.rgba[4 * i + 3] < 0.999f) continue;
    ++covered;
    if (r.rgba[4 * i] < 0.2f) ++dark;
  }
  ASSERT_GT(covered, 500);
  EXPECT_EQ(dark, 0);
}

}  // namespace
}  // namespace mp::test
