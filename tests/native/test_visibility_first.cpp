// Visibility first (SampleStage::visibility, RenderSettings::visibility_first):
// the camera's batches find the depth of their opaque grids before shading
// and shade only the grids that own a sample. The image, its passes and the
// rasteriser's statistics are the same bit for bit with it on and off, for
// both samplers, with semi-transparent, alpha-cut and held-out surfaces
// among the opaque ones, and out of focus; the hidden grids go unshaded.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "pipeline/frame/visibility_choice.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class VisibilityFirstTest : public SharedRendererTest {
 protected:
  // Renders `s` with visibility first off and on; everything but the shading
  // work must agree. Returns the render with it on.
  RenderResult expect_same(Scene s, const char* what) {
    s.settings.visibility_first = VisibilityFirst::Off;
    const RenderResult off = renderer_->render(s);
    s.settings.visibility_first = VisibilityFirst::On;
    const RenderResult on = renderer_->render(s);
    EXPECT_FALSE(off.rgba.empty()) << what;
    EXPECT_EQ(on.rgba, off.rgba) << what << ": visibility first changed the image";
    EXPECT_EQ(on.depth, off.depth) << what;
    EXPECT_EQ(on.normal, off.normal) << what;
    EXPECT_EQ(on.stats.micropolygons_sampled, off.stats.micropolygons_sampled) << what;
    EXPECT_EQ(on.stats.sample_tests, off.stats.sample_tests) << what;
    EXPECT_EQ(on.stats.covered_pixels, off.stats.covered_pixels) << what;
    EXPECT_EQ(off.stats.subpatches_unshaded, 0u) << what;
    return on;
  }
};

// Closed Catmull-Clark cubes of half size 1, 1.5, 2, ... around the camera:
// the innermost half transparent, the next cut by an alpha program, the
// third held out where its Generated x passes one half, the rest opaque.
Scene shells() {
  Scene s = base_scene(256, 192, 16);
  s.camera = look_at({0.1f, 0.05f, 0.0f}, {1.0f, 0.3f, -0.6f}, 70.0f);
  Material glass;
  glass.model = Material::Model::Matte;
  glass.color = glm::vec3(0.9f, 0.5f, 0.3f);
  glass.opacity = glm::vec3(0.45f);
  s.materials.push_back(glass);
  add_program_material(s, "holes", "0.2f, 0.7f, 0.3f",
                       "if (sin(20.0f * g->generated.x) > 0.3f) mp_add_transparent(s, (float3)(1.0f));", true);
  add_program_material(s, "held", "0.3f, 0.3f, 0.8f", "if (g->generated.x > 0.5f) mp_add_holdout(s, (float3)(1.0f));",
                       false);
  for (int k = 0; k < 8; ++k) {
    Mesh m = cube_mesh(SubdivScheme::CatmullClark);
    m.name = "shell" + std::to_string(k);
    m.object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f + 0.5f * k));
    m.material = k < 3 ? k + 1 : 0;
    s.meshes.push_back(m);
  }
  return s;
}

TEST_F(VisibilityFirstTest, SameImageWithEitherSampler) {
  for (const Sampler sampler : {Sampler::Tiles, Sampler::Micropolygons, Sampler::Bins}) {
    Scene s = shells();
    s.settings.sampler = sampler;
    const char* what = sampler == Sampler::Tiles ? "tile sampler" : sampler == Sampler::Bins ? "bins" : "micropolygon sampler";
    const RenderResult on = expect_same(s, what);
    if (sampler == Sampler::Bins) EXPECT_EQ(on.stats.sampler, "bins");
    // Five opaque shells behind the cut ones: what culling leaves of them
    // owns no sample (about a sixth of the sub-patches diced).
    EXPECT_GT(on.stats.subpatches_unshaded, on.stats.subpatches_diced / 10) << what;
  }
}

TEST_F(VisibilityFirstTest, SameImageOutOfFocusAndWithoutCulling) {
  Scene s = shells();
  s.camera.lens_radius = 0.05f;
  s.camera.focus_distance = 2.0f;
  EXPECT_GT(expect_same(s, "depth of field").stats.subpatches_unshaded, 0u);
  s = shells();
  s.settings.occlusion_culling = false;
  EXPECT_GT(expect_same(s, "culling off").stats.subpatches_unshaded, 0u);
}

// Auto takes it on CPU devices where hidden shading costs more than the
// passes: 30 stacked layers 2 cm apart under a soft-shadowed lamp (each
// vertex filters its shadow); the image is the one without it. A facing
// plane hides nothing, and Auto leaves it off.
Scene stacked_layers() {
  Scene s = base_scene(192, 144, 16);
  s.lights.clear();
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.position = glm::vec3(0.3f, -0.4f, 2.0f);
  lamp.intensity = 30.0f;
  lamp.radius = 0.3f;
  s.lights.push_back(lamp);
  s.camera = look_at({0.0f, -3.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 50.0f);
  for (int k = 0; k < 30; ++k) {
    Mesh m = grid_mesh(6, 4.0f, SubdivScheme::CatmullClark);
    m.name = "layer" + std::to_string(k);
    m.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -0.02f * float(k)));
    s.meshes.push_back(m);
  }
  return s;
}

TEST_F(VisibilityFirstTest, AutoTakesItWhereHiddenShadingCostsMore) {
  if (renderer_->device().type != "cpu") GTEST_SKIP() << "Auto leaves it off on GPUs";
  Scene layers = stacked_layers();
  layers.settings.visibility_first = VisibilityFirst::Off;
  const RenderResult off = renderer_->render(layers);
  layers.settings.visibility_first = VisibilityFirst::Auto;
  const RenderResult automatic = renderer_->render(layers);
  EXPECT_EQ(automatic.rgba, off.rgba);
  EXPECT_GT(automatic.stats.subpatches_unshaded, automatic.stats.subpatches_diced / 4)
      << automatic.stats.subpatches_unshaded << " of " << automatic.stats.subpatches_diced << " unshaded";
  Scene flat = base_scene(128, 96, 4);
  flat.camera = look_at({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, 0.0f});
  flat.meshes.push_back(polygon({{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}}));
  EXPECT_EQ(renderer_->render(flat).stats.subpatches_unshaded, 0u);
  flat.settings.visibility_first = VisibilityFirst::On;
  EXPECT_EQ(renderer_->render(flat).stats.subpatches_unshaded, 0u);  // every grid of a facing plane is seen
}

}  // namespace
}  // namespace mp::test

namespace mp::test {
namespace {

// Auto's choice from a batch's measurements (pipeline/frame/visibility_choice.h).
VisibilityChoice::Batch plain(double shade_ms, double sample_ms, size_t micropolygons, size_t lost) {
  VisibilityChoice::Batch b;
  b.shade_ms = shade_ms, b.sample_ms = sample_ms, b.grids = micropolygons / 200;
  b.micropolygons = micropolygons, b.lost = lost;
  return b;
}

TEST(VisibilityChoice, TakenWhereHiddenShadingCostsMoreThanThePasses) {
  VisibilityChoice c(true, false);
  EXPECT_FALSE(c.take());  // the first batch: nothing measured yet
  // Half hidden, shading three times the sampling: 150 ms saved, for
  // passes guessed at 90 (0.9 of the sampling; 1.25 times that to start).
  c.measured(plain(300.0, 100.0, 100000, 50000));
  EXPECT_TRUE(c.take());
  // It took it and left 60 % of its grids unshaded; the shaded 40 % cost 40 ms.
  VisibilityChoice::Batch took;
  took.took = true, took.passes_ms = 50.0, took.shade_ms = 40.0, took.grids = 500, took.micropolygons = 100000;
  took.unshaded = 300;
  c.measured(took);
  EXPECT_TRUE(c.take());
  // Nothing hidden any more: off again.
  took.unshaded = 0;
  c.measured(took);
  EXPECT_FALSE(c.take());
}

TEST(VisibilityChoice, LeftOffWhereShadingIsCheapOrLittleIsHidden) {
  VisibilityChoice c(true, false);
  c.measured(plain(60.0, 180.0, 100000, 30000));  // a matte teapot: shading a third of sampling
  EXPECT_FALSE(c.take());
  c.measured(plain(300.0, 100.0, 100000, 1000));  // expensive shading, 1 % hidden
  EXPECT_FALSE(c.take());
  // Saved just above the passes' cost but within the starting margin.
  c.measured(plain(100.0, 100.0, 100000, 100000));  // 100 ms saved for 90
  EXPECT_FALSE(c.take());
}

TEST(VisibilityChoice, HiddenShadingCostIsSolvedFromBothKindsOfBatch) {
  VisibilityChoice c(true, false);
  c.measured(plain(300.0, 100.0, 100000, 50000));
  ASSERT_TRUE(c.take());
  // Seen micropolygons cost 1 us to shade here, so at an average of 3 us
  // with half hidden, hidden ones cost 5 us: 20,000 hidden save 100 ms
  // (the average alone would say 60) for 80 ms of passes.
  VisibilityChoice::Batch took;
  took.took = true, took.passes_ms = 80.0, took.grids = 500, took.micropolygons = 100000, took.unshaded = 100;
  took.shade_ms = 80.0;  // 80,000 seen micropolygons at 1 us
  c.measured(took);
  EXPECT_TRUE(c.take());
}

TEST(VisibilityChoice, TheSettingOverridesMeasurement) {
  VisibilityChoice on(false, true), off(false, false);
  on.measured(plain(1.0, 100.0, 100000, 0));
  off.measured(plain(300.0, 1.0, 100000, 90000));
  EXPECT_TRUE(on.take());
  EXPECT_FALSE(off.take());
}

}  // namespace
}  // namespace mp::test
