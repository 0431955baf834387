// The tile sampler (kernels/stages/sample_tiles.cl) against the per-micropolygon
// sampler (kernels/stages/sample.cl), and frames rendered in buckets
// (pipeline/frame/buckets.h) against the whole frame: the same winner for every
// sample, so the same image (buckets: bit for bit), on whichever device runs
// the tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "pipeline/frame/buckets.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A torus, a sphere and a floor: silhouettes, depth overlap, back faces.
Scene test_scene(int width, int height, int spp) {
  Scene s = base_scene(width, height, spp);
  s.camera = look_at({0.4f, 2.2f, 4.5f}, {0.0f, 0.0f, 0.0f}, 50.0f);
  Mesh torus = torus_mesh(24, 12, 0.35f, SubdivScheme::CatmullClark);
  torus.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(-0.7f, 0.4f, 0.0f));
  torus.double_sided = false;
  s.meshes.push_back(torus);
  Mesh sphere = uv_sphere_mesh(12, 24);
  sphere.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.8f, 0.5f, -0.3f));
  s.meshes.push_back(sphere);
  Mesh floor = grid_mesh(4, 4.0f, SubdivScheme::None);
  floor.object_to_world = glm::rotate(glm::mat4(1.0f), -1.5707963f, glm::vec3(1, 0, 0));
  s.meshes.push_back(floor);
  return s;
}

double psnr(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0.0;
  for (size_t i = 0; i < a.size(); ++i) se += double(a[i] - b[i]) * double(a[i] - b[i]);
  const double mse = se / double(std::max<size_t>(a.size(), 1));
  return mse > 0.0 ? 10.0 * std::log10(1.0 / mse) : 1000.0;
}

bool alpha_identical(const RenderResult& a, const RenderResult& b) {
  if (a.rgba.size() != b.rgba.size()) return false;
  for (size_t i = 3; i < a.rgba.size(); i += 4)
    if (a.rgba[i] != b.rgba[i]) return false;
  return true;
}

class SampleTilesTest : public SharedRendererTest {
 protected:
  // Renders s with each sampler; both images (and passes) must be the same.
  void expect_samplers_agree(Scene s, const char* what) {
    s.settings.sampler = Sampler::Micropolygons;
    const RenderResult a = renderer_->render(s);
    s.settings.sampler = Sampler::Tiles;
    const RenderResult b = renderer_->render(s);
    ASSERT_FALSE(a.rgba.empty());
    // The same winner for every sample: the Depth pass (each pixel's nearest
    // sample) is identical; colors differ only by the order in which the
    // resolve adds samples (16 at a time on the tile sampler's planar
    // colors), a few units in the last place.
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    float worst = 0.0f;
    for (size_t i = 0; i < a.rgba.size(); ++i) worst = std::max(worst, std::fabs(a.rgba[i] - b.rgba[i]));
    EXPECT_LT(worst, 1e-5f) << what;
    EXPECT_GE(psnr(a.rgba, b.rgba), 100.0) << what;
    EXPECT_EQ(a.depth, b.depth) << what;
    EXPECT_EQ(a.normal, b.normal) << what;
    EXPECT_EQ(a.stats.sample_tests, b.stats.sample_tests) << what << ": a sampler tested other samples";
    EXPECT_GT(a.stats.covered_pixels, 0u) << what;
  }
};

TEST_F(SampleTilesTest, TilesChooseTheSameWinnerAsMicropolygons) {
  expect_samplers_agree(test_scene(320, 240, 16), "16 spp");
  expect_samplers_agree(test_scene(300, 200, 9), "9 spp (lanes past the pixel's samples)");
  expect_samplers_agree(test_scene(256, 192, 36), "36 spp (three chunks of 16)");
}

TEST_F(SampleTilesTest, SlowPathsAgreeToo) {
  // Semi-transparent: stochastic opacity per sample (the 64-bit path).
  Scene glass = test_scene(320, 240, 16);
  Material m = glass.materials[0];
  m.opacity = glm::vec3(0.45f);
  glass.materials.push_back(m);
  glass.meshes[1].material = 1;
  expect_samplers_agree(glass, "semi-transparent sphere");
  // Micropolygons tens of pixels across: too large for the int32 path.
  Scene coarse = test_scene(320, 240, 4);
  coarse.settings.shading_rate = 2500.0f;
  expect_samplers_agree(coarse, "micropolygons of 50 px");
  // Micropolygons about 30 px across, whose bounds fall on both sides of
  // MP_FAST_SPAN (32 px): each sampler's int32 path and its 64-bit one.
  Scene edge = test_scene(320, 240, 4);
  edge.settings.shading_rate = 900.0f;
  expect_samplers_agree(edge, "micropolygons of 30 px");
  // A crop window: the sample pattern follows whole-image pixels.
  Scene crop = test_scene(320, 240, 16);
  crop.settings.crop_x0 = 0.3f, crop.settings.crop_x1 = 0.85f;
  crop.settings.crop_y0 = 0.1f, crop.settings.crop_y1 = 0.6f;
  expect_samplers_agree(crop, "crop window");
}

// A 1080p frame in buckets (a sample budget of 16 MiB) against the whole
// frame: every filter's reach is covered by the buckets' margins.
TEST_F(SampleTilesTest, BucketsEqualTheWholeFrame) {
  struct Case {
    PixelFilter filter;
    float width;
    Sampler sampler;
  };
  for (const Case c : {Case{PixelFilter::Gaussian, 2.0f, Sampler::Auto},
                       Case{PixelFilter::BlackmanHarris, 4.0f, Sampler::Tiles},
                       Case{PixelFilter::Box, 1.0f, Sampler::Micropolygons}}) {
    Scene s = test_scene(1920, 1080, 4);
    s.settings.filter = c.filter;
    s.settings.filter_width = c.width;
    s.settings.sampler = c.sampler;
    const RenderResult whole = renderer_->render(s);
    s.settings.sample_memory_mib = 16.0f;
    const RenderResult tiled = renderer_->render(s);
    EXPECT_EQ(whole.stats.buckets, 1u);
    EXPECT_GE(tiled.stats.buckets, 8u);
    ASSERT_EQ(whole.rgba.size(), tiled.rgba.size());
    EXPECT_GE(psnr(whole.rgba, tiled.rgba), 60.0) << "filter width " << c.width;
    EXPECT_TRUE(alpha_identical(whole, tiled)) << "filter width " << c.width;
    size_t depth_differs = 0, first = 0;
    for (size_t i = whole.depth.size(); i-- > 0;)
      if (whole.depth[i] != tiled.depth[i]) ++depth_differs, first = i;
    EXPECT_EQ(depth_differs, 0u) << "first at pixel " << first % 1920 << ", " << first / 1920 << ": "
                                 << (depth_differs ? whole.depth[first] : 0.0f) << " vs "
                                 << (depth_differs ? tiled.depth[first] : 0.0f);
    EXPECT_EQ(whole.stats.covered_pixels, tiled.stats.covered_pixels);
  }
}

// With a progress callback the tile sampler launches its tiles in parts and
// asks between them; the image is the same, and a cancel stops the render.
TEST_F(SampleTilesTest, ProgressAndCancelAcrossTileParts) {
  Scene s = test_scene(1280, 720, 16);
  s.settings.sampler = Sampler::Tiles;
  const RenderResult plain = renderer_->render(s);
  int asked = 0;
  const RenderResult watched = renderer_->render(s, [&](float p) {
    EXPECT_GE(p, 0.0f);
    EXPECT_LE(p, 1.0f);
    ++asked;
    return true;
  });
  EXPECT_GT(asked, 3);
  EXPECT_EQ(plain.rgba, watched.rgba);
  int calls = 0;
  const RenderResult cancelled = renderer_->render(s, [&](float) { return ++calls < 3; });
  EXPECT_TRUE(cancelled.stats.cancelled);
  EXPECT_TRUE(cancelled.rgba.empty());
  // The renderer goes on working after a cancel.
  EXPECT_EQ(renderer_->render(s).rgba, plain.rgba);
}

TEST(BucketPlan, CoversTheFrameOnceWithinTheBudget) {
  for (const int reach : {0, 1, 2}) {
    const int w = 7680, h = 4320, spp = 64;
    const size_t max_samples = (size_t(2048) << 20) / 24;
    const std::vector<Bucket> buckets = plan_buckets(w, h, spp, reach, max_samples);
    ASSERT_GT(buckets.size(), 1u);
    std::vector<unsigned char> hit(size_t(w) * h, 0);
    for (const Bucket& b : buckets) {
      EXPECT_LE(b.sample_pixels() * spp, max_samples);
      EXPECT_EQ(b.sx0, std::max(0, b.x0 - reach));
      EXPECT_EQ(b.sx1, std::min(w, b.x1 + reach));
      EXPECT_EQ(b.sy0, std::max(0, b.y0 - reach));
      EXPECT_EQ(b.sy1, std::min(h, b.y1 + reach));
      for (int y = b.y0; y < b.y1; ++y)
        for (int x = b.x0; x < b.x1; ++x) ++hit[size_t(y) * w + x];
    }
    for (unsigned char n : hit) ASSERT_EQ(n, 1);
  }
  EXPECT_EQ(plan_buckets(1920, 1080, 16, 1, size_t(1920) * 1080 * 16).size(), 1u);
  EXPECT_THROW(plan_buckets(1920, 1080, 64, 1, 1000), Error);
}

TEST_F(SampleTilesTest, BadSampleMemoryIsAClearError) {
  for (const float mib : {0.0f, 0.5f, -64.0f, std::nanf(""), INFINITY}) {
    Scene s = test_scene(64, 48, 4);
    s.settings.sample_memory_mib = mib;
    try {
      renderer_->render(s);
      ADD_FAILURE() << "a sample memory of " << mib << " MiB rendered";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("sample memory"), std::string::npos) << e.what();
    }
  }
}

TEST_F(SampleTilesTest, TooSmallABudgetIsAClearError) {
  Scene s = test_scene(320, 240, 1024);
  s.settings.sample_memory_mib = 1.0f;
  try {
    renderer_->render(s);
    FAIL() << "a 1 MiB budget at 1024 spp rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sample memory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mp::test
