// Scene fingerprints (pipeline/device_scene/scene_fingerprint.h): the scene's changes
// whenever anything rendered changes, node values included; the shadow
// maps' (geometry_fingerprint) only when what a shadow view reads does.
#include <gtest/gtest.h>

#include "micropoly/scene.h"
#include "pipeline/device_scene/scene_fingerprint.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

Scene two_materials() {
  Scene s = base_scene(32, 32, 1);
  s.meshes.push_back(polygon({{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}}));
  s.material_programs.push_back({"p", "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n"});
  s.materials[0].program = 0;
  s.materials[0].program_shades = true;
  s.materials[0].program_params = {0.2f, 0.3f};
  return s;
}

TEST(SceneFingerprint, NodeValuesChangeTheSceneButOnlyShadowRelevantOnesTheShadows) {
  const Scene base = two_materials();
  Scene colour = base;
  colour.materials[0].program_params[0] = 0.9f;  // a colour: shading only
  EXPECT_NE(scene_fingerprint(colour), scene_fingerprint(base));
  EXPECT_EQ(geometry_fingerprint(colour), geometry_fingerprint(base));
  Scene plain = base;
  plain.materials[0].color = glm::vec3(0.1f);
  EXPECT_NE(scene_fingerprint(plain), scene_fingerprint(base));
  EXPECT_EQ(geometry_fingerprint(plain), geometry_fingerprint(base));

  // A program that displaces, or computes the alpha, shapes the shadows.
  for (int which = 0; which < 2; ++which) {
    Scene shaped = base;
    (which ? shaped.materials[0].program_alpha : shaped.materials[0].program_displaces) = true;
    Scene edited = shaped;
    edited.materials[0].program_params[1] = 0.7f;
    EXPECT_NE(geometry_fingerprint(shaped), geometry_fingerprint(base)) << which;
    EXPECT_NE(geometry_fingerprint(edited), geometry_fingerprint(shaped)) << which;
  }
  Scene opaque = base;
  opaque.materials[0].opacity = glm::vec3(0.5f);
  EXPECT_NE(geometry_fingerprint(opaque), geometry_fingerprint(base));
}

}  // namespace
}  // namespace mp::test
