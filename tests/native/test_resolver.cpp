// The resolve's two kernels (RenderSettings::resolver): the tiled one, which
// loads each work-group's samples and the filter's reach around them into
// local memory, and the per-pixel one must give the same image to float
// rounding, with the same alpha, Depth and Normal, for every filter reach,
// sample count, both samplers' colour layouts, held-out samples, crops that
// start off the tile grid, and frames cut into buckets (whose margins the
// tiles must read exactly as the pixels do).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class ResolverTest : public SharedRendererTest {
 protected:
  // Renders `s` with each kernel and compares.
  void expect_same(Scene s, const std::string& what) {
    s.settings.resolver = Resolver::Pixels;
    const RenderResult pixels = renderer_->render(s);
    s.settings.resolver = Resolver::Tiles;
    const RenderResult tiles = renderer_->render(s);
    ASSERT_EQ(pixels.stats.resolver, "pixels") << what;
    ASSERT_EQ(tiles.stats.resolver, "tiles") << what << ": the tiled kernel was not taken";
    ASSERT_EQ(tiles.rgba.size(), pixels.rgba.size()) << what;
    ASSERT_FALSE(pixels.rgba.empty()) << what;
    float worst = 0.0f, lit = 0.0f;
    size_t partial = 0;  // pixels of fractional alpha: the filter's edges
    for (size_t i = 0; i < pixels.rgba.size(); ++i) {
      ASSERT_TRUE(std::isfinite(tiles.rgba[i])) << what << " at " << i;
      worst = std::max(worst, std::fabs(tiles.rgba[i] - pixels.rgba[i]));
      lit = std::max(lit, pixels.rgba[i]);
      if (i % 4 == 3 && pixels.rgba[i] > 0.01f && pixels.rgba[i] < 0.99f) ++partial;
    }
    EXPECT_GT(lit, 0.05f) << what << ": nothing rendered";
    EXPECT_GT(partial, 0u) << what << ": no edges to compare";
    // The same sums in another order: a few float roundings of values <= 1.
    EXPECT_LE(worst, 2e-6f) << what;
    EXPECT_EQ(tiles.depth, pixels.depth) << what;
    EXPECT_EQ(tiles.normal, pixels.normal) << what;
  }

  // A subdivided torus in front of a wall, cut by the frame's edges, with a
  // half-transparent sphere and a held-out square.
  static Scene busy(int width, int height, int spp) {
    Scene s = base_scene(width, height, spp);
    s.camera = look_at({0.4f, 1.2f, 4.0f}, {0.2f, 0.0f, 0.0f}, 50.0f);
    Material glass;
    glass.model = Material::Model::Matte;
    glass.color = glm::vec3(0.9f, 0.4f, 0.2f);
    glass.opacity = glm::vec3(0.5f);
    s.materials.push_back(glass);
    add_program_material(s, "held", "0.3f, 0.3f, 0.8f", "mp_add_holdout(s, (float3)(1.0f));", false);
    Mesh torus = torus_mesh(12, 8, 0.35f, SubdivScheme::CatmullClark);
    torus.object_to_world = glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(1, 0, 0));
    s.meshes.push_back(torus);
    Mesh wall = grid_mesh(4, 1.8f, SubdivScheme::None);  // behind, its corner in view
    wall.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(-1.0f, 0.6f, -1.5f));
    s.meshes.push_back(wall);
    Mesh ball = uv_sphere_mesh(8, 12);
    ball.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(1.2f, 0.2f, 0.8f)), glm::vec3(0.5f));
    ball.material = 1;
    s.meshes.push_back(ball);
    Mesh square = polygon({{-1.6f, -0.2f, 0.6f}, {-0.9f, -0.2f, 0.6f}, {-0.9f, 0.5f, 0.6f}, {-1.6f, 0.5f, 0.6f}});
    square.material = 2;
    s.meshes.push_back(square);
    return s;
  }
};

TEST_F(ResolverTest, SameImageForEveryFilterReach) {
  // Reach 0 (box 1), 1 (Blackman-Harris 3, Cycles' 1.5 px), 2 (Gaussian 4).
  const struct {
    PixelFilter filter;
    float width;
  } filters[] = {{PixelFilter::Box, 1.0f}, {PixelFilter::BlackmanHarris, 3.0f}, {PixelFilter::Gaussian, 4.0f},
                 {PixelFilter::Triangle, 2.0f}};
  for (const auto& fl : filters) {
    Scene s = busy(77, 53, 16);  // sizes off the 8-pixel tiles
    s.settings.filter = fl.filter;
    s.settings.filter_width = fl.width;
    expect_same(s, "filter " + std::to_string(int(fl.filter)) + " width " + std::to_string(fl.width));
  }
}

TEST_F(ResolverTest, SameImageForEverySampleCountAndBothSamplers) {
  for (int spp : {1, 4, 9, 16}) {
    for (Sampler sampler : {Sampler::Tiles, Sampler::Micropolygons}) {
      Scene s = busy(64, 40, spp);
      s.settings.filter = PixelFilter::BlackmanHarris;
      s.settings.filter_width = 3.0f;
      s.settings.sampler = sampler;
      expect_same(s, std::to_string(spp) + " spp, sampler " + std::to_string(int(sampler)));
    }
  }
}

TEST_F(ResolverTest, SameImageWithHoldoutsCoveredCroppedAndInBuckets) {
  Scene s = busy(96, 64, 16);
  s.settings.filter = PixelFilter::BlackmanHarris;
  s.settings.filter_width = 3.0f;
  s.settings.holdout_covers = true;
  expect_same(s, "held-out samples covering");
  s.settings.crop_x0 = 0.13f, s.settings.crop_x1 = 0.81f;
  s.settings.crop_y0 = 0.21f, s.settings.crop_y1 = 0.9f;
  expect_same(s, "a crop off the tile grid");
  // 1 MiB of samples: the frame is cut into buckets, each resolved with
  // its margin of the filter's reach.
  s.settings.sample_memory_mib = 1.0f;
  s.settings.crop_x0 = 0.0f, s.settings.crop_x1 = 1.0f, s.settings.crop_y0 = 0.0f, s.settings.crop_y1 = 1.0f;
  s.settings.depth_and_normal_passes = true;
  const RenderResult buckets = renderer_->render(s);
  EXPECT_GT(buckets.stats.buckets, 1u);
  expect_same(s, "buckets");
}

}  // namespace
}  // namespace mp::test
