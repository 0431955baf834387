// Occlusion culling (kernels/stages/mp_occlusion.h): images with culling on and off
// are the same, sample for sample, while hidden sub-patches are not diced.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "pipeline/frame/camera_view.h"
#include "renderer_fixture.h"
#include "rib/rib_reader.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class OcclusionTest : public SharedRendererTest {
 protected:
  // On CPU devices bound & split takes the roots in waves, sampling the
  // nearest before the rest are split (bound_split_bounded.cpp); the
  // lights' views take them in waves on CPUs only, and the camera on GPUs
  // only where its roots overlap deeply (stats.occlusion_waves). Elsewhere
  // the pyramid is rebuilt only between full dice batches, so a scene that
  // fits one batch culls nothing. How much is culled is checked where
  // waves ran; that the image does not change, everywhere.
  static bool lights_take_waves() { return renderer_->device().type == "cpu"; }
  struct Pair {
    RenderResult on, off;
  };
  // Renders `s` with culling off, then on, through both bound & split methods
  // with culling on; all images must be identical.
  Pair render_both(Scene s) {
    s.settings.occlusion_culling = false;
    Pair p;
    p.off = renderer_->render(s);
    s.settings.occlusion_culling = true;
    p.on = renderer_->render(s);
    s.settings.bound_split = BoundSplitMethod::Breadth;
    RenderResult breadth = renderer_->render(s);
    EXPECT_EQ(p.off.stats.subpatches_occluded, 0u);
    EXPECT_EQ(p.on.rgba, p.off.rgba) << "culling changed the image";
    EXPECT_EQ(p.on.depth, p.off.depth);
    EXPECT_EQ(breadth.rgba, p.off.rgba) << "culling changed the breadth-first image";
    EXPECT_EQ(p.on.stats.covered_pixels, p.off.stats.covered_pixels);
    return p;
  }
};

// Closed Catmull-Clark cubes of half size 1, 1.5, 2, ... around the camera.
Scene nested_shells(int n) {
  Scene s = base_scene(320, 240, 4);
  s.camera = look_at({0.1f, 0.05f, 0.0f}, {1.0f, 0.3f, -0.6f}, 70.0f);
  for (int k = 0; k < n; ++k) {
    Mesh m = cube_mesh(SubdivScheme::CatmullClark);
    m.name = "shell" + std::to_string(k);
    m.object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f + 0.5f * k));
    s.meshes.push_back(m);
  }
  return s;
}

// The quad [x0, x1] x [y0, y1] at height z, facing +z.
Mesh quad(float x0, float y0, float x1, float y1, float z) {
  return polygon({{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}});
}

// A camera above the origin looking down.
Scene top_view() {
  Scene s = base_scene(256, 256, 4);
  s.camera = look_at({0.0f, 0.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, 45.0f);
  return s;
}

Material colored(glm::vec3 c) {
  Material m;
  m.model = Material::Model::Matte;
  m.color = c;
  return m;
}

TEST_F(OcclusionTest, NestedShellsRenderTheSameWithTheHiddenOnesCulled) {
  Pair one = render_both(nested_shells(1));
  Pair eight = render_both(nested_shells(8));
  if (!eight.on.stats.occlusion_waves) GTEST_SKIP() << "the images agree; culling in a single batch needs waves";
  EXPECT_GT(eight.on.stats.subpatches_occluded, 0u);
  // Without culling, eight shells dice about eight times one; with it, the
  // outer seven cost little.
  EXPECT_GT(eight.off.stats.micropolygons, 5 * one.off.stats.micropolygons);
  EXPECT_LT(eight.on.stats.micropolygons, 1.5 * one.on.stats.micropolygons);
  EXPECT_LT(eight.on.stats.micropolygons, eight.off.stats.micropolygons / 3);
  // Depth complexity (surface layers rasterised per covered pixel): about
  // eight without culling; culled, what is left is the inner shell and
  // slivers of the next ones beside its parts sampled in the same batch.
  const double off_layers = eight.off.stats.sampled_area_px / eight.off.stats.covered_pixels;
  const double on_layers = eight.on.stats.sampled_area_px / eight.on.stats.covered_pixels;
  EXPECT_GT(off_layers, 5.0);
  EXPECT_LT(on_layers, 0.4 * off_layers);
}

TEST_F(OcclusionTest, TheShadowMarkingsDepthBringsTheSeenShellFirstOnEveryDevice) {
  // With a shadowed lamp, the shadow marking's coarse depth finds the roots
  // the camera may see; the camera takes those as a wave of their own, so
  // the outer shells are culled on every device, with the rest taken at
  // once (no waves after it), and the image is the one without culling.
  auto lit = [](Scene s) {
    s.settings.occlusion_waves = OcclusionWaves::Off;
    Light lamp;
    lamp.type = Light::Type::Point;
    lamp.intensity = 20.0f;
    lamp.position = glm::vec3(0.3f, 0.2f, -0.1f);
    lamp.radius = 0.05f;
    s.lights.push_back(lamp);
    return s;
  };
  Pair one = render_both(lit(nested_shells(1)));
  Pair eight = render_both(lit(nested_shells(8)));
  ASSERT_GT(eight.on.stats.shadows.pages_requested, 0u);
  EXPECT_GT(eight.off.stats.micropolygons, 5 * one.off.stats.micropolygons);
  // Taken at once without that wave (a GPU), eight shells diced 7.9 times
  // one shell's micropolygons; with it, 1.55 times.
  EXPECT_LT(eight.on.stats.micropolygons, 2 * one.on.stats.micropolygons);
}

TEST_F(OcclusionTest, WavesOnAndOffRenderTheSameAndWavesCullTheHiddenShells) {
  // RenderSettings::occlusion_waves forced either way on any device: the
  // image is the same; taken at once (no shadows, so no seen wave first),
  // eight shells are diced whole in one batch, while waves sample the
  // inner shell before the outer ones are split.
  Scene s = nested_shells(8);
  s.settings.shadows = false;
  s.settings.occlusion_waves = OcclusionWaves::On;
  const RenderResult on = renderer_->render(s);
  s.settings.occlusion_waves = OcclusionWaves::Off;
  const RenderResult off = renderer_->render(s);
  EXPECT_EQ(on.rgba, off.rgba);
  EXPECT_EQ(on.depth, off.depth);
  EXPECT_TRUE(on.stats.occlusion_waves);
  EXPECT_FALSE(off.stats.occlusion_waves);
  EXPECT_GT(on.stats.waves, 2u);
  EXPECT_EQ(off.stats.waves, 1u);
  EXPECT_LT(on.stats.micropolygons, off.stats.micropolygons / 3);
  // The estimate Auto reads: boxes around the camera count as covering the
  // whole frame, so eight shells' 48 patches overlap deeply.
  EXPECT_GT(off.stats.root_overlap, 8.0);
}

TEST(CameraWaves, AutoTakesThemOnCpusAndOnGpusWhereTheRootsOverlapDeeply) {
  RenderSettings s;
  DeviceInfo cpu, gpu;
  cpu.type = "cpu", gpu.type = "gpu";
  EXPECT_TRUE(camera_takes_waves(s, cpu, 1.0));
  EXPECT_FALSE(camera_takes_waves(s, gpu, 13.0));
  EXPECT_TRUE(camera_takes_waves(s, gpu, kGpuWavesFromOverlap));
  EXPECT_TRUE(camera_takes_waves(s, gpu, 1332.0));
  s.occlusion_waves = OcclusionWaves::Off;
  EXPECT_FALSE(camera_takes_waves(s, cpu, 1332.0));
  s.occlusion_waves = OcclusionWaves::On;
  EXPECT_TRUE(camera_takes_waves(s, gpu, 1.0));
}

TEST_F(OcclusionTest, TheFarSurfaceShowsThroughASmallHole) {
  // An occluder with a 3 x 3 pixel hole in its middle over a far plane of
  // another colour: the hole's pixels must keep the far plane.
  Scene s = top_view();
  s.materials.push_back(colored({0.9f, 0.1f, 0.1f}));  // 1: far, red
  s.materials.push_back(colored({0.1f, 0.1f, 0.9f}));  // 2: near, blue
  Mesh far = quad(-3, -3, 3, 3, 0.0f);
  far.material = 1;
  s.meshes.push_back(far);
  // At distance 4 with a 45 degree view over 256 pixels, a pixel is about
  // 2 * 4 * tan(22.5 deg) / 256 = 0.013 units; the hole is 0.04 wide.
  const float h = 0.02f, z = 2.0f;
  for (Mesh m : {quad(-3, -3, 3, -h, z), quad(-3, h, 3, 3, z), quad(-3, -h, -h, h, z), quad(h, -h, 3, h, z)}) {
    m.material = 2;
    s.meshes.push_back(m);
  }
  Pair p = render_both(s);
  if (p.on.stats.occlusion_waves) EXPECT_GT(p.on.stats.subpatches_occluded, 0u);
  const size_t centre = (128 * 256 + 128) * 4;
  EXPECT_GT(p.on.rgba[centre], 2 * p.on.rgba[centre + 2]) << "the hole does not show the red far plane";
  const size_t beside = (128 * 256 + 100) * 4;
  EXPECT_GT(p.on.rgba[beside + 2], 2 * p.on.rgba[beside]) << "the occluder is not blue beside the hole";
}

TEST_F(OcclusionTest, SemiTransparentSurfacesDoNotHideWhatIsBehindThem) {
  // A half-transparent plane in front of an opaque one in front of a third:
  // the middle plane shows through the first, and the third stays hidden.
  Scene s = top_view();
  s.materials.push_back(colored({0.9f, 0.1f, 0.1f}));
  s.materials.push_back(colored({0.1f, 0.9f, 0.1f}));
  Material glass = colored({0.1f, 0.1f, 0.9f});
  glass.opacity = glm::vec3(0.5f);
  s.materials.push_back(glass);
  Mesh back = quad(-3, -3, 3, 3, -1.0f), middle = quad(-3, -3, 3, 3, 0.0f), front = quad(-3, -3, 3, 3, 2.0f);
  back.material = 1, middle.material = 2, front.material = 3;
  for (const Mesh& m : {back, middle, front}) s.meshes.push_back(m);
  Pair p = render_both(s);
  const size_t centre = (128 * 256 + 128) * 4;
  EXPECT_GT(p.on.rgba[centre + 1], 0.2f) << "the opaque plane does not show through the transparent one";
  EXPECT_LT(p.on.rgba[centre], 0.5f * p.on.rgba[centre + 1]) << "the hidden plane shows";
}

TEST_F(OcclusionTest, DisplacedSurfacesRenderTheSame) {
  // A sheet displaced towards the camera in bumps over a second sheet: the
  // displacement bound keeps what bulges out of the hidden sheet's bound.
  Scene s = top_view();
  s.material_programs.push_back(
      {"bumps",
       "float3 mp_node_displacement(const MpNodeGlobals* g) {\n"
       "  float h = 0.6f * sin(9.0f * g->P.x) * sin(7.0f * g->P.y);\n"
       "  return (float3)(0.0f, 0.0f, h);\n}\n"
       "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n"});
  Material bumpy = colored({0.8f, 0.7f, 0.2f});
  bumpy.program = 0;
  bumpy.program_displaces = true;
  bumpy.displacement_bound = 0.6f;
  s.materials.push_back(bumpy);
  s.materials.push_back(colored({0.2f, 0.6f, 0.8f}));
  Mesh near = grid_mesh(8, 3.0f, SubdivScheme::CatmullClark);
  near.material = 2;
  near.object_to_world = glm::translate(glm::mat4(1.0f), {0.0f, 0.0f, 0.5f});
  Mesh bumps = grid_mesh(8, 3.0f, SubdivScheme::CatmullClark);
  bumps.material = 1;
  s.meshes.push_back(bumps);
  s.meshes.push_back(near);
  Pair p = render_both(s);
  // The bumps rise through the flat sheet in places: both colours show.
  size_t yellow = 0, blue = 0;
  for (size_t i = 0; i < p.on.rgba.size(); i += 4) {
    yellow += p.on.rgba[i] > p.on.rgba[i + 2] + 0.1f;
    blue += p.on.rgba[i + 2] > p.on.rgba[i] + 0.1f;
  }
  EXPECT_GT(yellow, 1000u);
  EXPECT_GT(blue, 1000u);
}

TEST_F(OcclusionTest, TheWorldsProbeSunsCullInOnePassAndRenderTheSame) {
  // Stacked quads over a floor under a uniform world whose eight probe suns
  // cast shadows: their views share one culling pass (ShadowLayout's
  // cull_group), each culling against its own pages; the image is the
  // same as without culling, and the stack's hidden quads are culled.
  Scene s = top_view();
  for (int k = 0; k < 6; ++k) {
    Mesh layer = grid_mesh(8, 6.0f, SubdivScheme::None);
    layer.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 0.2f * float(k)));
    s.meshes.push_back(layer);
  }
  s.world.width = 2, s.world.height = 1;
  s.world.radiance.assign(8, 1.0f);
  s.world.cast_shadows = true;
  s.settings.world_probes = 8;
  s.settings.keep_shadow_pages = false;  // every render renders its pages
  const Pair p = render_both(s);
  EXPECT_GT(p.on.stats.shadows.lights, 1);
  EXPECT_GT(p.on.stats.shadows.views, 1u);
  if (lights_take_waves()) {
    EXPECT_GT(p.on.stats.shadows.subpatches_occluded, 0u);
    EXPECT_LT(p.on.stats.shadows.micropolygons, p.off.stats.shadows.micropolygons);
  }
}

TEST_F(OcclusionTest, TestScenesRenderTheSame) {
  for (const char* name : {"teapot.rib", "torus_closeup.rib", "subdiv_creases.rib"}) {
    SCOPED_TRACE(name);
    Scene s = read_rib_file(std::string(MICROPOLY_TEST_SCENES) + "/" + name).scene;
    render_both(s);
  }
}

}  // namespace
}  // namespace mp::test
