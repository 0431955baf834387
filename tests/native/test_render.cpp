// End-to-end renders through the OpenCL pipeline on the default device.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "micropoly/settings_util.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class RenderTest : public SharedRendererTest {};

// Raster position of a world point, as the renderer maps it (RenderMan screen
// window: the shorter image side spans [-1, 1]).
glm::vec2 project(const Scene& s, glm::vec3 p) {
  glm::vec3 c = glm::vec3(s.camera.world_to_camera * glm::vec4(p, 1.0f));
  float t = std::tan(glm::radians(s.camera.fov_degrees) * 0.5f);
  float aspect = float(s.settings.width) / float(s.settings.height);
  float sx = c.x / (-c.z * t), sy = c.y / (-c.z * t);
  float l = aspect >= 1 ? -aspect : -1, r = -l, b = aspect >= 1 ? -1 : -1 / aspect, top = -b;
  return {(sx - l) / (r - l) * s.settings.width, (top - sy) / (top - b) * s.settings.height};
}

double projected_area(const Scene& s, const std::vector<glm::vec3>& pts) {
  double a = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    glm::vec2 p = project(s, pts[i]), q = project(s, pts[(i + 1) % pts.size()]);
    a += double(p.x) * q.y - double(q.x) * p.y;
  }
  return std::abs(a) * 0.5;
}

TEST_F(RenderTest, FlatPolygonCoverageMatchesProjectedArea) {
  // A tilted quad, a triangle and a pentagon, each seen in perspective.
  std::vector<std::vector<glm::vec3>> shapes = {
      {{-1.2f, -0.8f, 0.3f}, {1.1f, -1.0f, -0.4f}, {0.9f, 1.1f, -0.2f}, {-1.0f, 0.7f, 0.5f}},
      {{-1.0f, -1.0f, 0.0f}, {1.3f, -0.6f, -0.5f}, {-0.2f, 1.2f, 0.4f}},
      {{0.0f, -1.2f, 0.0f}, {1.1f, -0.3f, 0.2f}, {0.7f, 1.0f, 0.0f}, {-0.7f, 1.0f, -0.3f}, {-1.1f, -0.3f, 0.1f}}};
  for (const auto& pts : shapes) {
    Scene s = base_scene(320, 240, 16);
    s.camera = look_at({0.5f, 0.3f, 5.0f}, {0, 0, 0}, 40.0f);
    s.meshes.push_back(polygon(pts));
    RenderResult r = renderer_->render(s);
    double expected = projected_area(s, pts);
    ASSERT_GT(expected, 2000.0);
    EXPECT_NEAR(coverage(r) / expected, 1.0, 0.005) << pts.size() << "-gon, expected " << expected << " px";
  }
}

TEST_F(RenderTest, SameSceneRendersBitIdenticallyTwice) {
  Scene s = base_scene(200, 150, 4);
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  RenderResult a = renderer_->render(s), b = renderer_->render(s);
  ASSERT_GT(coverage(a), 1000.0);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.normal, b.normal);
}

// The renderer keeps the last scene's device buffers for a re-render of the
// same content. Re-rendering at another sample count or size reuses them;
// any change to geometry, transforms, camera placement, materials or lights
// must not, and must show in the image.
TEST_F(RenderTest, SceneBuffersAreReusedOnlyForTheSameContent) {
  Scene s = base_scene(200, 150, 4);
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.lights.push_back(Light{});
  s.lights.back().position = glm::vec3(3.0f, 4.0f, 5.0f);
  s.lights.back().intensity = 20.0f;
  RenderResult first = renderer_->render(s);
  ASSERT_GT(coverage(first), 1000.0);
  RenderResult again = renderer_->render(s);
  EXPECT_TRUE(again.stats.scene_reused);
  EXPECT_EQ(first.rgba, again.rgba);

  Scene more = s;
  set_samples_per_pixel(more.settings, 16);
  more.settings.width = 100, more.settings.height = 75;
  RenderResult small = renderer_->render(more);
  EXPECT_TRUE(small.stats.scene_reused) << "samples and size do not change the scene's buffers";

  auto changed = [&](const char* what, auto edit) {
    Scene t = s;
    edit(t);
    RenderResult r = renderer_->render(t);
    EXPECT_FALSE(r.stats.scene_reused) << what;
    EXPECT_NE(r.rgba, first.rgba) << what;
    renderer_->render(s);  // back to the original for the next case
  };
  changed("a moved vertex", [](Scene& t) { t.meshes[0].points[0] += glm::vec3(0.3f, 0.2f, 0.4f); });
  changed("an object transform", [](Scene& t) {
    t.meshes[0].object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.2f, 0.0f, 0.0f));
  });
  changed("the camera placement", [](Scene& t) { t.camera = look_at({2.4f, 2.1f, 4.0f}, {0, 0, 0}); });
  changed("a material colour", [](Scene& t) { t.materials[0].color = glm::vec3(0.2f, 0.9f, 0.3f); });
  changed("a light", [](Scene& t) { t.lights[0].intensity = 5.0f; });
}

TEST_F(RenderTest, BoundedAndBreadthFirstProduceTheSameImage) {
  Scene s = base_scene(256, 192, 4);
  s.camera = look_at({0.0f, -3.0f, 2.5f}, {0, 0, 0}, 60.0f);
  s.meshes.push_back(grid_mesh(12, 3.0f, SubdivScheme::CatmullClark));
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.meshes.back().object_to_world = glm::scale(glm::translate(glm::mat4(1), {0.5f, 0.5f, 0.6f}), glm::vec3(0.5f));
  s.settings.bound_split = BoundSplitMethod::Bounded;
  s.settings.bound_split_memory_mib = 2.0f;
  s.settings.occlusion_culling = false;  // it culls by what earlier batches sampled, which the methods order differently
  RenderResult bounded = renderer_->render(s);
  s.settings.bound_split = BoundSplitMethod::Breadth;
  RenderResult breadth = renderer_->render(s);
  EXPECT_EQ(bounded.stats.subpatches_diced, breadth.stats.subpatches_diced);
  EXPECT_EQ(bounded.stats.micropolygons, breadth.stats.micropolygons);
  EXPECT_GT(bounded.stats.micropolygons, 10000u);
  EXPECT_EQ(bounded.rgba, breadth.rgba);
  EXPECT_EQ(bounded.depth, breadth.depth);
}

TEST_F(RenderTest, BoundedStaysWithinBudgetWhereBreadthFirstExceedsIt) {
  // A large, finely split plane: the breadth-first queue gets wide.
  Scene s = base_scene(640, 480, 1);
  s.camera = look_at({0.0f, -6.0f, 1.2f}, {0, 2, 0}, 70.0f);
  s.meshes.push_back(grid_mesh(100, 20.0f, SubdivScheme::None));
  const float budget_mib = 0.5f;
  s.settings.bound_split = BoundSplitMethod::Bounded;
  s.settings.bound_split_memory_mib = budget_mib;
  s.settings.shading_rate = 0.25f;
  s.settings.occlusion_culling = false;  // the methods' diced sets are compared
  RenderResult bounded = renderer_->render(s);
  s.settings.bound_split = BoundSplitMethod::Breadth;
  RenderResult breadth = renderer_->render(s);
  const size_t budget = static_cast<size_t>(budget_mib * 1048576);
  EXPECT_LE(bounded.stats.bound_split_peak_bytes, budget);
  EXPECT_GT(breadth.stats.bound_split_peak_bytes, budget);
  EXPECT_EQ(bounded.stats.subpatches_diced, breadth.stats.subpatches_diced);
  EXPECT_EQ(bounded.rgba, breadth.rgba);
}

TEST_F(RenderTest, PlaneThroughTheEyePlaneRendersInBoundedTimeAndMemory) {
  // A ground plane running under and behind the camera: its patches straddle
  // the eye plane and must be eye-split, then culled at the depth limit. A
  // second plane passes through the eye itself.
  Scene s = base_scene(320, 240, 4);
  s.camera = look_at({0.0f, 0.0f, 0.5f}, {0.0f, 5.0f, 0.0f}, 60.0f);
  s.meshes.push_back(grid_mesh(2, 50.0f, SubdivScheme::None));
  Mesh through_eye = grid_mesh(1, 30.0f, SubdivScheme::None);
  through_eye.object_to_world =
      glm::translate(glm::mat4(1), {0.0f, 0.0f, 0.5f}) * glm::rotate(glm::mat4(1), glm::radians(90.0f), glm::vec3(0, 1, 0));
  s.meshes.push_back(through_eye);
  s.settings.bound_split_memory_mib = 4.0f;
  auto t0 = std::chrono::steady_clock::now();
  RenderResult r = renderer_->render(s);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 60.0);
  EXPECT_LE(r.stats.bound_split_peak_bytes, size_t(4) << 20);
  // The ground fills the lower part of the frame up to the horizon.
  EXPECT_GT(coverage(r), 0.4 * 320 * 240);
  size_t bottom_centre = (239 * 320 + 160) * 4;
  EXPECT_NEAR(r.rgba[bottom_centre + 3], 1.0f, 1e-6f);
  for (float v : r.rgba) ASSERT_TRUE(std::isfinite(v));
  s.settings.bound_split = BoundSplitMethod::Breadth;
  RenderResult b = renderer_->render(s);
  EXPECT_EQ(r.rgba, b.rgba);
}

TEST_F(RenderTest, SingleSidedBackFacesAreCulled) {
  Scene s = base_scene(64, 64, 1);
  s.camera = look_at({0, 0, 4}, {0, 0, 0});
  Mesh front = polygon({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}});
  front.double_sided = false;
  s.meshes.push_back(front);
  EXPECT_GT(coverage(renderer_->render(s)), 500.0);
  std::reverse(s.meshes[0].face_vertex_indices.begin(), s.meshes[0].face_vertex_indices.end());
  EXPECT_EQ(coverage(renderer_->render(s)), 0.0);
  s.meshes[0].double_sided = true;
  EXPECT_GT(coverage(renderer_->render(s)), 500.0);
}

TEST_F(RenderTest, DepthAndNormalPassesDescribeAPlaneFacingTheCamera) {
  Scene s = base_scene(64, 64, 4);
  s.camera = look_at({0, 0, 5}, {0, 0, 0});
  s.meshes.push_back(polygon({{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}}));
  RenderResult r = renderer_->render(s);
  size_t centre = 32 * 64 + 32;
  EXPECT_NEAR(r.depth[centre], 5.0f, 1e-3f);
  EXPECT_NEAR(r.normal[3 * centre + 2], 1.0f, 1e-3f);  // world +Z, towards the camera
  EXPECT_NEAR(r.rgba[4 * centre + 3], 1.0f, 1e-6f);
}

TEST_F(RenderTest, PixelFiltersAreNormalised) {
  // A constant-color plane filling the frame: every filter must give exactly
  // that color and full coverage, inside and at the image border.
  for (PixelFilter filter : {PixelFilter::Box, PixelFilter::Gaussian, PixelFilter::Triangle}) {
    Scene s = base_scene(48, 32, 9);
    s.materials[0].model = Material::Model::Constant;
    s.materials[0].color = glm::vec3(0.25f, 0.5f, 2.0f);
    s.settings.filter = filter;
    s.settings.filter_width = filter == PixelFilter::Box ? 1.0f : 3.0f;
    s.camera = look_at({0, 0, 2}, {0, 0, 0});
    s.meshes.push_back(polygon({{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}}));
    RenderResult r = renderer_->render(s);
    for (size_t i = 0; i < size_t(48 * 32); ++i) {
      ASSERT_NEAR(r.rgba[4 * i + 0], 0.25f, 1e-5f) << "pixel " << i;
      ASSERT_NEAR(r.rgba[4 * i + 1], 0.5f, 1e-5f) << "pixel " << i;
      ASSERT_NEAR(r.rgba[4 * i + 2], 2.0f, 1e-5f) << "pixel " << i;
      ASSERT_NEAR(r.rgba[4 * i + 3], 1.0f, 1e-6f) << "pixel " << i;
    }
  }
}

TEST_F(RenderTest, CropWindowRendersTheSamePixelsAsTheFullFrame) {
  Scene s = base_scene(64, 48, 4);
  s.camera = look_at({2.5f, 2.0f, 4.0f}, {0, 0, 0});
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.settings.filter = PixelFilter::Box;
  RenderResult full = renderer_->render(s);
  s.settings.crop_x0 = 0.25f, s.settings.crop_x1 = 0.75f, s.settings.crop_y0 = 0.5f, s.settings.crop_y1 = 1.0f;
  RenderResult crop = renderer_->render(s);
  ASSERT_EQ(crop.width, 32);
  ASSERT_EQ(crop.height, 24);
  // Samples follow whole-image pixels, so with a box filter the crop's pixels
  // are exactly the full frame's.
  double diff = 0, sum = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x)
      for (int c = 0; c < 4; ++c) {
        float a = crop.rgba[4 * (y * 32 + x) + c], b = full.rgba[4 * ((y + 24) * 64 + x + 16) + c];
        diff += std::abs(a - b);
        sum += std::abs(b);
      }
  EXPECT_GT(sum, 100.0);
  EXPECT_EQ(diff, 0.0);
}

TEST_F(RenderTest, EmptySceneGivesATransparentImage) {
  Scene s = base_scene(32, 32, 1);
  RenderResult r = renderer_->render(s);
  EXPECT_EQ(coverage(r), 0.0);
  EXPECT_EQ(r.stats.patches, 0u);
}

TEST_F(RenderTest, InvalidSceneIsRejectedWithTheObjectName) {
  Scene s = base_scene(32, 32, 1);
  Mesh m = polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  m.name = "broken";
  m.points[1].x = std::nanf("");
  s.meshes.push_back(m);
  try {
    renderer_->render(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken"), std::string::npos) << e.what();
  }
}

// Finite but enormous coordinates (single-precision bounds overflow) are
// refused by validation, by world position: the object's transform counts.
TEST_F(RenderTest, CoordinatesBeyondTheWorldLimitAreRefused) {
  auto render_with = [&](float reach, float scale) {
    Scene s = base_scene(32, 32, 1);
    Mesh m = polygon({{-reach, -reach, 0}, {reach, -reach, 0}, {0, reach, 0}});
    m.name = "far";
    m.object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(scale));
    s.meshes.push_back(m);
    renderer_->render(s);
  };
  render_with(1e14f, 1.0f);
  for (auto [reach, scale] : {std::pair{3e38f, 1.0f}, std::pair{1e25f, 1.0f}, std::pair{1e13f, 1e3f}}) {
    try {
      render_with(reach, scale);
      FAIL() << "expected an error for " << reach << " x " << scale;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("mesh 'far': point 0 lies"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("beyond 1e15"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mp::test
