// The binned sampler (kernels/stages/sample_bins.cl) against the
// per-micropolygon sampler (kernels/stages/sample.cl): both keep sample
// colours in the same layout and resolve them with the same kernel, so the
// same winner for every sample makes the same image bit for bit, on
// whichever device runs the tests.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A torus seen through a sphere's silhouette, a cube crossing the sphere
// (equal depths along the seam), and a floor under them running off the
// frame's edges, so bins at the frame's border are partly outside it.
Scene bins_scene(int width, int height, int spp) {
  Scene s = base_scene(width, height, spp);
  s.camera = look_at({0.3f, 1.6f, 3.8f}, {0.0f, 0.2f, 0.0f}, 55.0f);
  Mesh torus = torus_mesh(20, 10, 0.3f, SubdivScheme::CatmullClark);
  torus.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.4f, 0.3f, -0.8f));
  torus.double_sided = false;
  s.meshes.push_back(torus);
  Mesh sphere = uv_sphere_mesh(10, 20);
  sphere.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(-0.2f, 0.5f, 0.2f));
  s.meshes.push_back(sphere);
  Mesh cube = cube_mesh(SubdivScheme::None);
  cube.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(-0.6f, 0.3f, 0.3f)), glm::vec3(0.4f));
  s.meshes.push_back(cube);
  Mesh floor = grid_mesh(6, 8.0f, SubdivScheme::None);
  floor.object_to_world = glm::rotate(glm::mat4(1.0f), -1.5707963f, glm::vec3(1, 0, 0));
  s.meshes.push_back(floor);
  return s;
}

class SampleBinsTest : public SharedRendererTest {
 protected:
  // Renders s with the per-micropolygon sampler and with bins: the same
  // image, passes and counts; `bins` whether the frame could take bins.
  RenderResult expect_same(Scene s, const char* what, bool bins = true) {
    s.settings.sampler = Sampler::Micropolygons;
    const RenderResult a = renderer_->render(s);
    s.settings.sampler = Sampler::Bins;
    RenderResult b = renderer_->render(s);
    EXPECT_EQ(a.stats.sampler, "micropolygons") << what;
    EXPECT_EQ(b.stats.sampler, bins ? "bins" : "micropolygons") << what;
    EXPECT_FALSE(a.rgba.empty()) << what;
    EXPECT_GT(a.stats.covered_pixels, 0u) << what;
    EXPECT_TRUE(a.rgba == b.rgba) << what;
    EXPECT_TRUE(a.depth == b.depth) << what;
    EXPECT_TRUE(a.normal == b.normal) << what;
    EXPECT_EQ(a.stats.covered_pixels, b.stats.covered_pixels) << what;
    return b;
  }
};

TEST_F(SampleBinsTest, BinsChooseTheSameWinnerAsMicropolygons) {
  // Bins of 16 px (16 spp), 32 px (4 and 1 spp) and 8 px (36 spp), and
  // frames whose last row and column of bins are partly outside them.
  expect_same(bins_scene(320, 240, 16), "16 spp");
  expect_same(bins_scene(301, 203, 4), "4 spp, odd size");
  expect_same(bins_scene(200, 150, 1), "1 spp");
  expect_same(bins_scene(250, 170, 36), "36 spp");
}

TEST_F(SampleBinsTest, WideRunsTransparencyCropAndBucketsAgree) {
  // Micropolygons of about 50 px: their runs reach more bins than a list
  // takes (MP_BIN_RUN_TILES), so the per-micropolygon sampler takes them
  // beside the bins; the floor's near part mixes both.
  Scene coarse = bins_scene(320, 240, 4);
  coarse.settings.shading_rate = 2500.0f;
  expect_same(coarse, "micropolygons of 50 px");
  // Semi-transparent: stochastic opacity per sample (the 64-bit path).
  Scene glass = bins_scene(320, 240, 16);
  Material m = glass.materials[0];
  m.opacity = glm::vec3(0.45f);
  glass.materials.push_back(m);
  glass.meshes[1].material = 1;
  expect_same(glass, "semi-transparent sphere");
  Scene crop = bins_scene(320, 240, 16);
  crop.settings.crop_x0 = 0.3f, crop.settings.crop_x1 = 0.85f;
  crop.settings.crop_y0 = 0.1f, crop.settings.crop_y1 = 0.6f;
  expect_same(crop, "crop window");
  Scene buckets = bins_scene(640, 480, 16);
  buckets.settings.sample_memory_mib = 8.0f;
  EXPECT_GE(expect_same(buckets, "buckets").stats.buckets, 2u);
}

TEST_F(SampleBinsTest, FramesBinsCannotTakeUseThePerMicropolygonSampler) {
  // 256 spp: even a bin of 8 px holds 128 KiB of keys.
  expect_same(bins_scene(64, 48, 256), "256 spp", false);
  Scene blurred = bins_scene(160, 120, 16);
  blurred.camera.lens_radius = 0.05f;
  blurred.camera.focus_distance = 3.0f;
  expect_same(blurred, "depth of field", false);
}

TEST(SampleBins, BinSideFitsTheKeysInLocalMemory) {
  EXPECT_EQ(SampleStage::bin_side(16, 48 * 1024), 16);
  EXPECT_EQ(SampleStage::bin_side(4, 48 * 1024), 32);
  EXPECT_EQ(SampleStage::bin_side(1, 48 * 1024), 32);
  EXPECT_EQ(SampleStage::bin_side(64, 48 * 1024), 8);
  EXPECT_EQ(SampleStage::bin_side(65, 48 * 1024), 0);
  // 8 KiB of the device's local memory are kept from the keys: with 16 KiB
  // a bin of 8 px fits at 16 spp, with 12 KiB none does.
  EXPECT_EQ(SampleStage::bin_side(16, 16 * 1024), 8);
  EXPECT_EQ(SampleStage::bin_side(16, 12 * 1024), 0);
  EXPECT_EQ(SampleStage::bin_side(1, 4 * 1024), 0);
  for (const int spp : {1, 4, 9, 16, 36, 64})
    for (const size_t local : {size_t(20) << 10, size_t(48) << 10, size_t(4) << 20}) {
      const int side = SampleStage::bin_side(spp, local);
      if (side) EXPECT_LE(size_t(side) * side * spp * 8, std::min(SampleStage::kBinKeyBytes, local - 8192));
    }
}

}  // namespace
}  // namespace mp::test
