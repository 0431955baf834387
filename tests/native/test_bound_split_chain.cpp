// Chained bound & split launches (RenderSettings::bound_split_chain,
// bs_bounded_control in bound_split.cl): the device sets each next launch's
// counters by the host's rules, so a chain of launches must split exactly as
// launches read back one by one. The image, its passes and the diced and
// culled counts of the camera's and the lights' views are the same bit for
// bit with and without chains (the number of launches is not: which worker
// takes which work is a race between work-groups, with or without chains), with occlusion culling (whose waves the host still
// decides), soft shadows of a point lamp (many views in one pass) and a
// budget small enough that workers hand work through a full ring; and the
// chains take fewer host reads.
#include <gtest/gtest.h>

#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

size_t waits_in(const RenderStats& st, const std::string& phase) {
  size_t n = 0;
  for (const auto& [name, count] : st.host_waits_by_phase)
    if (name.find(phase) != std::string::npos) n += count;
  return n;
}

class BoundSplitChainTest : public SharedRendererTest {
 protected:
  // Nested subdivided cubes and a floor under a soft point lamp and a sun.
  static Scene shells(int spp) {
    Scene s = base_scene(160, 120, spp);
    s.camera = look_at({0.6f, 1.4f, 5.5f}, {0.0f, 0.2f, 0.0f}, 55.0f);
    s.lights[1].cast_shadows = true;
    s.settings.keep_shadow_pages = false;  // every render renders its lights' views
    Light lamp;
    lamp.type = Light::Type::Point;
    lamp.position = glm::vec3(1.5f, 3.0f, 2.0f);
    lamp.intensity = 20.0f;
    lamp.radius = 0.3f;
    s.lights.push_back(lamp);
    for (int k = 0; k < 4; ++k) {
      Mesh m = cube_mesh(SubdivScheme::CatmullClark);
      m.name = "shell" + std::to_string(k);
      m.object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(0.6f + 0.35f * k));
      s.meshes.push_back(m);
    }
    Mesh floor = grid_mesh(6, 5.0f, SubdivScheme::None);
    floor.object_to_world = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0, -1.6f, 0)), -1.5707964f,
                                        glm::vec3(1, 0, 0));
    s.meshes.push_back(floor);
    return s;
  }

  // `longer`: the passes run several launches between stops (no culling
  // waves), so chains must save host reads; otherwise they must not add any.
  void expect_same(Scene s, const char* what, bool longer) {
    s.settings.bound_split_chain = 1;
    const RenderResult one = renderer_->render(s);
    for (int chain : {2, 5, 16}) {
      s.settings.bound_split_chain = chain;
      const RenderResult chained = renderer_->render(s);
      const std::string at = std::string(what) + ", chains of " + std::to_string(chain);
      EXPECT_EQ(chained.rgba, one.rgba) << at;
      EXPECT_EQ(chained.depth, one.depth) << at;
      EXPECT_EQ(chained.normal, one.normal) << at;
      EXPECT_EQ(chained.stats.subpatches_diced, one.stats.subpatches_diced) << at;
      EXPECT_EQ(chained.stats.micropolygons, one.stats.micropolygons) << at;
      EXPECT_EQ(chained.stats.subpatches_occluded, one.stats.subpatches_occluded) << at;
      EXPECT_EQ(chained.stats.shadows.micropolygons, one.stats.shadows.micropolygons) << at;
      EXPECT_EQ(chained.stats.shadows.subpatches_occluded, one.stats.shadows.subpatches_occluded) << at;
      if (longer)
        EXPECT_LT(waits_in(chained.stats, "bound_split"), waits_in(one.stats, "bound_split")) << at;
      else
        EXPECT_LE(waits_in(chained.stats, "bound_split"), waits_in(one.stats, "bound_split")) << at;
    }
    EXPECT_GT(one.stats.micropolygons, 10000u) << what;
    EXPECT_GT(one.stats.shadows.micropolygons, 1000u) << what;
    EXPECT_GT(one.stats.bound_split_launches, 10u) << what;
  }
};

TEST_F(BoundSplitChainTest, ChainsSplitAsLaunchesReadOneByOne) {
  Scene s = shells(4);
  expect_same(s, "culling on", false);  // waves of one launch or two on CPUs
  s.settings.occlusion_culling = false;
  expect_same(s, "culling off", true);
}

TEST_F(BoundSplitChainTest, ChainsSplitAlikeWithinASmallBudget) {
  // 0.5 MiB: a few hundred workers and a ring as small, full most launches.
  Scene s = shells(1);
  s.settings.bound_split_memory_mib = 0.5f;
  s.settings.shading_rate = 0.2f;
  expect_same(s, "a 0.5 MiB budget", false);
  s.settings.occlusion_culling = false;
  expect_same(s, "a 0.5 MiB budget without culling", true);
}

// Steps per launch (RenderSettings::bound_split_steps): 1 on GPUs, 16 on
// CPUs by default. Fewer steps hand work out between launches sooner and
// change which batch dices what, never the image; without culling, whose
// pyramid follows the batches, nor what is diced.
TEST_F(BoundSplitChainTest, StepsPerLaunchChangeNeitherTheImageNorWhatIsDiced) {
  for (bool culling : {true, false}) {
    Scene s = shells(4);
    s.settings.occlusion_culling = culling;
    s.settings.bound_split_steps = 16;
    const RenderResult sixteen = renderer_->render(s);
    for (int steps : {1, 3}) {
      s.settings.bound_split_steps = steps;
      const RenderResult r = renderer_->render(s);
      const std::string at = std::to_string(steps) + " steps, culling " + (culling ? "on" : "off");
      EXPECT_EQ(r.rgba, sixteen.rgba) << at;
      EXPECT_EQ(r.depth, sixteen.depth) << at;
      EXPECT_EQ(r.normal, sixteen.normal) << at;
      if (!culling) {
        EXPECT_EQ(r.stats.subpatches_diced, sixteen.stats.subpatches_diced) << at;
        EXPECT_EQ(r.stats.shadows.micropolygons, sixteen.stats.shadows.micropolygons) << at;
      }
      // One step a launch takes more launches (three may take as many as
      // sixteen where the device runs every worker the tree can use at once).
      if (steps == 1)
        EXPECT_GT(r.stats.bound_split_launches, sixteen.stats.bound_split_launches) << at;
      else
        EXPECT_GE(r.stats.bound_split_launches, sixteen.stats.bound_split_launches) << at;
    }
  }
}

}  // namespace
}  // namespace mp::test
