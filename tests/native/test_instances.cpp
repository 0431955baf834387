// Instancing (scene.h Prototype and Instance): an instanced scene renders
// like the same scene with its instances made real by hand, with
// displacement, motion blur, mirroring, reversed orientation, material and
// sidedness overrides and Object Info; RIB's ObjectBegin/ObjectInstance
// read and write them; bad instances are refused with a message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "renderer_fixture.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A displaced, subdivided cube (prototype 0: its own material, one face in
// another) and a Bezier patch beside it (prototype 1), placed six times.
Scene instanced_scene() {
  Scene s = base_scene(96, 72, 4);
  s.camera = look_at({0.0f, -9.0f, 5.0f}, {0.0f, 0.0f, 0.0f}, 50.0f);
  // Material 1 colours by Object Info's random and by an Attribute node of
  // type Instancer (slot 1), and displaces in object space.
  s.material_programs.push_back(
      {"bumpy",
       "float3 mp_node_displacement(const MpNodeGlobals* g) {\n"
       "  return g->N * (0.08f * sin(11.0f * g->P.x) * sin(9.0f * g->P.z));\n}\n"
       "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {\n"
       "  float r = g->object ? g->object->info[1] : 0.0f;\n"
       "  float4 a = mp_object_attribute(g, 1u);\n"
       "  mp_add_diffuse(s, (float3)(0.2f + 0.7f * r, 0.2f + 0.7f * a.y, 0.9f - 0.7f * r), 0, 0.0f);\n}\n"});
  Material bumpy;
  bumpy.model = Material::Model::Principled;
  bumpy.program = 0;
  bumpy.program_displaces = true;
  bumpy.program_shades = true;
  bumpy.displacement_bound = 0.08f;
  s.materials.push_back(bumpy);
  Material red;
  red.model = Material::Model::Matte;
  red.color = {0.8f, 0.1f, 0.1f};
  s.materials.push_back(red);

  Prototype cube;
  cube.name = "cube";
  Mesh m = cube_mesh(SubdivScheme::CatmullClark);
  m.name = "body";
  m.material = 1;
  m.face_materials.assign(m.face_vertex_counts.size(), 1);
  m.face_materials[2] = 2;
  m.object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(0.7f));  // the surface within its prototype
  m.double_sided = false;
  cube.meshes.push_back(m);
  s.prototypes.push_back(cube);

  Prototype sheet;
  sheet.name = "sheet";
  BezierPatches b;
  b.name = "patch";
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      b.control_points.emplace_back(-0.6f + 0.4f * i, -0.6f + 0.4f * j, (i == 1 || i == 2) && (j == 1 || j == 2) ? 0.5f : 0.0f);
  b.material = 2;
  sheet.bezier_patches.push_back(b);
  s.prototypes.push_back(sheet);

  auto place = [&](int proto, glm::vec3 at, float angle, glm::vec3 scale) {
    Instance inst;
    inst.prototype = proto;
    inst.object_to_world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), at), angle, glm::vec3(0, 0, 1)), scale);
    inst.info.random = float(s.instances.size()) / 6.0f;
    inst.info.pass_index = float(s.instances.size());
    // Two attribute slots, the second read by material 1; the third
    // instance carries only the first, and so reads zero in the second.
    inst.info.attributes = {glm::vec4(0.5f, 0.25f, 0.0f, 1.0f), glm::vec4(0.0f, 1.0f - inst.info.random, 0.0f, 1.0f)};
    if (s.instances.size() == 2) inst.info.attributes.pop_back();
    s.instances.push_back(inst);
    return &s.instances.back();
  };
  place(0, {-3.0f, 0.0f, 0.0f}, 0.3f, glm::vec3(1.0f));
  place(0, {-1.0f, 0.5f, 0.0f}, 1.1f, {1.0f, 1.4f, 0.8f});  // non-uniform scale
  place(0, {1.0f, 0.0f, 0.2f}, -0.4f, {-1.0f, 1.0f, 1.0f})->double_sided = 0;  // mirrored, one-sided
  Instance* reversed = place(0, {3.0f, 0.5f, 0.0f}, 0.0f, glm::vec3(0.8f));
  reversed->reverse_orientation = true;
  reversed->material = 2;  // RIB's material current at ObjectInstance
  place(1, {-1.5f, -2.0f, -1.0f}, 0.2f, glm::vec3(2.0f))->cast_shadows = false;
  place(1, {1.5f, -2.0f, -1.0f}, -0.2f, glm::vec3(2.0f));
  return s;
}

// The same instances made real by this test's own reading of scene.h.
Scene copies_by_hand(const Scene& s) {
  Scene out = s;
  out.prototypes.clear();
  out.instances.clear();
  for (const Instance& inst : s.instances) {
    const Prototype& p = s.prototypes[size_t(inst.prototype)];
    for (Mesh m : p.meshes) {
      for (const glm::mat4& t : inst.motion_object_to_world) m.motion_object_to_world.push_back(t * m.object_to_world);
      m.object_to_world = inst.object_to_world * m.object_to_world;
      if (inst.material >= 0) m.material = inst.material;
      if (inst.double_sided >= 0) m.double_sided = inst.double_sided == 1;
      m.cast_shadows = m.cast_shadows && inst.cast_shadows;
      m.visible_camera = m.visible_camera && inst.visible_camera;
      m.info = inst.info;
      if (inst.reverse_orientation) {
        size_t at = 0;
        for (int n : m.face_vertex_counts) {
          std::reverse(m.face_vertex_indices.begin() + long(at), m.face_vertex_indices.begin() + long(at) + n);
          at += size_t(n);
        }
      }
      out.meshes.push_back(m);
    }
    for (BezierPatches b : p.bezier_patches) {
      b.object_to_world = inst.object_to_world * b.object_to_world;
      if (inst.material >= 0) b.material = inst.material;
      if (inst.double_sided >= 0) b.double_sided = inst.double_sided == 1;
      b.cast_shadows = b.cast_shadows && inst.cast_shadows;
      b.visible_camera = b.visible_camera && inst.visible_camera;
      b.info = inst.info;
      out.bezier_patches.push_back(b);
    }
  }
  return out;
}

double psnr(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0.0;
  for (size_t i = 0; i < a.size(); ++i) se += double(a[i] - b[i]) * double(a[i] - b[i]);
  const double mse = se / double(std::max<size_t>(a.size(), 1));
  return mse == 0.0 ? 200.0 : 10.0 * std::log10(1.0 / mse);
}

// Same image (>= 60 dB), the same alpha to the bit, and something drawn.
void expect_same_image(const RenderResult& a, const RenderResult& b, const std::string& what) {
  ASSERT_EQ(a.rgba.size(), b.rgba.size()) << what;
  const double db = psnr(a.rgba, b.rgba);
  std::printf("%s: %.1f dB\n", what.c_str(), db);
  EXPECT_GE(db, 60.0) << what;
  size_t alpha_diff = 0, covered = 0;
  for (size_t i = 3; i < a.rgba.size(); i += 4) {
    alpha_diff += a.rgba[i] != b.rgba[i];
    covered += a.rgba[i] > 0.0f;
  }
  EXPECT_EQ(alpha_diff, 0u) << what;
  EXPECT_GT(covered, a.rgba.size() / 4 / 10) << what;
}

class InstancesTest : public SharedRendererTest {};

TEST_F(InstancesTest, RenderLikeTheirCopiesMadeByHand) {
  const Scene s = instanced_scene();
  expect_same_image(renderer_->render(s), renderer_->render(copies_by_hand(s)), "still");
}

TEST_F(InstancesTest, AttributesReachTheirInstancesMaterial) {
  // Each instance's own attribute colours it: without them the image
  // differs, far beyond the 60 dB within which images count as the same.
  const Scene s = instanced_scene();
  Scene none = s;
  for (Instance& inst : none.instances) inst.info.attributes.clear();
  const double db = psnr(renderer_->render(s).rgba, renderer_->render(none).rgba);
  std::printf("attributes against none: %.1f dB\n", db);
  EXPECT_LT(db, 45.0);
}

TEST_F(InstancesTest, MovingInstancesBlurLikeTheirCopies) {
  Scene s = instanced_scene();
  s.motion_steps = 3;
  for (Instance& inst : s.instances) {
    if (inst.prototype != 0) continue;  // patches do not move
    for (int k = 0; k < 3; ++k)
      inst.motion_object_to_world.push_back(glm::translate(glm::mat4(1.0f), {0.25f * float(k - 1), 0.0f, 0.1f * float(k)}) *
                                            inst.object_to_world);
  }
  const RenderResult a = renderer_->render(s), b = renderer_->render(copies_by_hand(s));
  expect_same_image(a, b, "motion blur");
  // The blur is there: the moving scene differs from the still one.
  EXPECT_LT(psnr(a.rgba, renderer_->render(instanced_scene()).rgba), 40.0);
}

TEST_F(InstancesTest, MadeRealMatchesTheRendering) {
  // with_instances_made_real, the scene's own reference, agrees with the
  // copies made by hand object for object.
  const Scene s = instanced_scene();
  const Scene real = with_instances_made_real(s), hand = copies_by_hand(s);
  ASSERT_EQ(real.meshes.size(), hand.meshes.size());
  ASSERT_EQ(real.bezier_patches.size(), hand.bezier_patches.size());
  for (size_t i = 0; i < real.meshes.size(); ++i) {
    EXPECT_EQ(real.meshes[i].object_to_world, hand.meshes[i].object_to_world);
    EXPECT_EQ(real.meshes[i].face_vertex_indices, hand.meshes[i].face_vertex_indices);
    EXPECT_EQ(real.meshes[i].material, hand.meshes[i].material);
    EXPECT_EQ(real.meshes[i].double_sided, hand.meshes[i].double_sided);
    EXPECT_TRUE(real.meshes[i].info == hand.meshes[i].info);
  }
  EXPECT_TRUE(real.prototypes.empty() && real.instances.empty());
}

TEST_F(InstancesTest, EveryPathOfThePipelineRendersThemLikeCopies) {
  // Bound & split breadth-first, the per-micropolygon sampler, buckets (a
  // sample budget too small for the frame), and no shadows.
  const Scene base = instanced_scene();
  for (int c = 0; c < 4; ++c) {
    Scene s = base;
    if (c == 0) s.settings.bound_split = BoundSplitMethod::Breadth;
    if (c == 1) s.settings.sampler = Sampler::Micropolygons;
    if (c == 2) {  // 11 MiB of samples in buckets of 2
      s.settings.width = 200, s.settings.height = 150;
      set_samples_per_pixel(s.settings, 16);
      s.settings.sample_memory_mib = 2.0f;
    }
    if (c == 3) s.settings.shadows = false;
    expect_same_image(renderer_->render(s), renderer_->render(copies_by_hand(s)), "path " + std::to_string(c));
  }
}

// A field of n x n instances of a subdivided sphere-like cube behind a wall
// (the camera sees the wall and, over it, the last rows).
Scene field_behind_wall(int n) {
  Scene s = base_scene(96, 72, 4);
  s.camera = look_at({0.0f, -12.0f, 2.0f}, {0.0f, 0.0f, 0.0f}, 50.0f);
  Prototype rock;
  rock.name = "rock";
  rock.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  s.prototypes.push_back(rock);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      Instance inst;
      inst.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), {-6.0f + 12.0f * i / (n - 1), 1.0f + 8.0f * j / (n - 1), 0.0f}),
                                        glm::vec3(0.35f));
      s.instances.push_back(inst);
    }
  Mesh wall = grid_mesh(2, 1.0f, SubdivScheme::None);
  wall.object_to_world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), {0.0f, -2.0f, 0.0f}), 1.5708f, {1, 0, 0}),
                                    {9.0f, 1.6f, 1.0f});
  s.meshes.push_back(wall);
  return s;
}

TEST_F(InstancesTest, PatchesAreUploadedOncePerPrototype) {
  const Scene s = field_behind_wall(12);
  const HostSceneData data = prepare_scene_data(s);
  Scene one = s;
  one.instances.resize(1);
  const size_t proto_patches = prepare_scene_data(one).patches.size() - prepare_scene_data(one).own_patches;
  EXPECT_GT(proto_patches, 0u);
  EXPECT_EQ(data.patches.size(), data.own_patches + proto_patches);  // not once per instance
  EXPECT_EQ(data.instances.size(), s.instances.size());
  // One root per instance (its prototype's tree), not one per placed patch.
  EXPECT_EQ(data.root_count, data.own_patches + s.instances.size());
  EXPECT_EQ(data.instanced_patches, s.instances.size() * proto_patches);
  EXPECT_EQ(data.patch_nodes.size(), proto_patches - 1);  // a binary tree over the prototype's patches
  for (const DeviceInstance& in : data.instances) EXPECT_EQ(in.root, data.instances[0].root);
  // Nearest the camera first.
  for (size_t i = 1; i < data.instances.size(); ++i)
    EXPECT_GE(data.instances[i - 1].box_hi[2], data.instances[i].box_hi[2]);
}

TEST_F(InstancesTest, InstancesBehindAWallAreCulledWholeAndTheImageStays) {
  Scene s = field_behind_wall(12);
  // Waves (the wall sampled before the field is split) on every device;
  // GPUs take them only over deep overlaps by default.
  s.settings.occlusion_waves = OcclusionWaves::On;
  const RenderResult on = renderer_->render(s);
  s.settings.occlusion_culling = false;
  const RenderResult off = renderer_->render(s);
  expect_same_image(on, off, "occlusion culling");
  // Most instances hide behind the wall: culled whole, at their tree's
  // root, never patch by patch.
  EXPECT_GT(on.stats.subpatches_occluded, on.stats.instances / 2) << on.stats.instances << " instances";
  EXPECT_LT(on.stats.subpatches_occluded, on.stats.patches / 20) << on.stats.patches << " patches";
  EXPECT_LT(on.stats.subpatches_diced * 4, off.stats.subpatches_diced);
  expect_same_image(on, renderer_->render(copies_by_hand(field_behind_wall(12))), "copies");
}

// A far field of instances a pixel or less across, on a ground under a
// sun: bound & split drops the subtrees that fall between samples
// (RenderSettings::sample_culling) in the camera's view and the sun's
// shadow maps, so the instances cost the samples they cover, not their
// patches, and the image stays the same, still, moving, out of focus and
// in buckets.
TEST_F(InstancesTest, DistantInstancesCostTheSamplesTheyCover) {
  Scene base = instanced_scene();
  base.camera = look_at({0.0f, -30.0f, 3.0f}, {0.0f, 40.0f, 0.0f}, 50.0f);
  const Instance proto_cube = base.instances[0];
  base.instances.clear();
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      Instance inst = proto_cube;
      const float x = -30.0f + 60.0f * (float(i) + 0.37f * float(j % 3)) / 16.0f, y = 20.0f + 6.0f * float(j);
      inst.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), {x, y, 0.4f}), glm::vec3(0.5f));
      inst.info.random = float((i * 7 + j * 13) % 16) / 16.0f;
      base.instances.push_back(inst);
    }
  Mesh ground = grid_mesh(2, 1.0f, SubdivScheme::None);
  ground.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), {0.0f, 60.0f, 0.0f}), {80.0f, 90.0f, 1.0f});
  base.meshes.push_back(ground);
  for (int c = 0; c < 4; ++c) {
    Scene s = base;
    const char* what = c == 0 ? "still" : c == 1 ? "moving" : c == 2 ? "out of focus" : "in buckets";
    if (c == 1) {
      s.motion_steps = 2;
      for (Instance& inst : s.instances)
        inst.motion_object_to_world = {glm::translate(glm::mat4(1.0f), {-0.3f, 0.0f, 0.0f}) * inst.object_to_world,
                                       glm::translate(glm::mat4(1.0f), {0.3f, 0.0f, 0.2f}) * inst.object_to_world};
    }
    if (c == 2) {
      s.camera.focus_distance = 25.0f;
      s.camera.lens_radius = 0.05f;
    }
    if (c == 3) {  // a sample budget too small for the frame: several buckets, each with its own raster origin
      s.settings.width = 200, s.settings.height = 150;
      set_samples_per_pixel(s.settings, 16);
      s.settings.sample_memory_mib = 2.0f;
    }
    s.settings.keep_shadow_pages = false;  // both render the sun's maps
    const RenderResult on = renderer_->render(s);
    s.settings.sample_culling = false;
    const RenderResult off = renderer_->render(s);
    expect_same_image(on, off, what);
    if (c == 3) EXPECT_GT(on.stats.buckets, 1u);
    // Still, most of the field falls between samples; moving or blurred,
    // its bounds grow over the shutter or the lens, and at a finer
    // resolution and 16 samples (the buckets') the rocks cover more, so
    // fewer do.
    const bool sharp = c == 0;
    const size_t factor = sharp ? 4 : 1, slack = sharp ? 1 : 5;
    EXPECT_LT(on.stats.subpatches_diced * factor * slack, off.stats.subpatches_diced * (slack - !sharp)) << what;
    EXPECT_LT(on.stats.shadows.micropolygons * (sharp ? 2 : 1), off.stats.shadows.micropolygons) << what;
    std::printf("%s: %zu against %zu sub-patches diced, %zu against %zu in shadow maps' micropolygons\n", what,
                size_t(on.stats.subpatches_diced), size_t(off.stats.subpatches_diced),
                size_t(on.stats.shadows.micropolygons), size_t(off.stats.shadows.micropolygons));
  }
}

TEST_F(InstancesTest, MovingOneInstanceRendersItsShadowAnew) {
  // A renderer keeps shadow pages between frames where nothing changed;
  // an instance that moved must cast its shadow from where it is now.
  Scene s = instanced_scene();
  Renderer kept;
  kept.render(s);
  s.instances[1].object_to_world = glm::translate(s.instances[1].object_to_world, {0.0f, 1.5f, 0.6f});
  const RenderResult again = kept.render(s);
  Renderer fresh;
  expect_same_image(again, fresh.render(s), "moved instance");
}

// --- RIB ------------------------------------------------------------------------------

std::string to_rib(const Scene& s) {
  std::ostringstream out;
  write_rib(s, out, "", "");
  return out.str();
}

TEST_F(InstancesTest, RibWritesObjectsAndReadsThemBackAsInstances) {
  Scene s = instanced_scene();
  s.motion_steps = 2;
  // Steps either side of the transform, so that the shutter's centre the
  // reader interpolates is the instance's own.
  s.instances[0].motion_object_to_world = {glm::translate(glm::mat4(1.0f), {-0.25f, 0.0f, 0.0f}) * s.instances[0].object_to_world,
                                           glm::translate(glm::mat4(1.0f), {0.25f, 0.0f, 0.0f}) * s.instances[0].object_to_world};
  const std::string text = to_rib(s);
  EXPECT_NE(text.find("ObjectBegin 1"), std::string::npos);
  EXPECT_NE(text.find("ObjectInstance 2"), std::string::npos);
  const RibResult r = read_rib_string(text, "instances.rib", ".");
  for (const std::string& w : r.warnings) ADD_FAILURE() << "warning: " << w;
  ASSERT_EQ(r.scene.prototypes.size(), 2u);
  ASSERT_EQ(r.scene.instances.size(), s.instances.size());
  EXPECT_TRUE(r.scene.meshes.empty());
  for (size_t i = 0; i < s.instances.size(); ++i) {
    EXPECT_EQ(r.scene.instances[i].prototype, s.instances[i].prototype);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        EXPECT_NEAR(r.scene.instances[i].object_to_world[c][k], s.instances[i].object_to_world[c][k], 1e-5f);
    EXPECT_EQ(r.scene.instances[i].motion_object_to_world, s.instances[i].motion_object_to_world);
    EXPECT_EQ(r.scene.instances[i].reverse_orientation, s.instances[i].reverse_orientation);
    EXPECT_TRUE(r.scene.instances[i].info == s.instances[i].info);
  }
  expect_same_image(renderer_->render(s), renderer_->render(r.scene), "RIB round trip");
}

TEST_F(InstancesTest, RibWritesCopiesOfWhatAnObjectCannotHold) {
  // Surfaces of one prototype that disagree on their sidedness: a RIB
  // object definition holds no attributes, so its instances are copies.
  Scene s = instanced_scene();
  Mesh other = s.prototypes[0].meshes[0];
  other.double_sided = true;
  other.object_to_world = glm::translate(other.object_to_world, {0.0f, 0.0f, 1.5f});
  s.prototypes[0].meshes.push_back(other);
  const RibResult r = read_rib_string(to_rib(s), "copies.rib", ".");
  EXPECT_EQ(r.scene.meshes.size(), 8u);     // four instances of two surfaces
  EXPECT_EQ(r.scene.instances.size(), 2u);  // the sheets stay instances
  expect_same_image(renderer_->render(s), renderer_->render(r.scene), "copies");
}

TEST(RibInstancesRead, ObjectInstanceIsAnInstanceOfOnePrototype) {
  const RibResult r = read_rib_string(
      "WorldBegin\n"
      "ObjectBegin \"rock\"\n  Translate 0 0 1\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n"
      "ObjectBegin \"unused\"\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n"
      "AttributeBegin\nAttribute \"identifier\" \"name\" \"first\"\nTranslate 5 0 0\nSides 1\n"
      "ReverseOrientation\nObjectInstance \"rock\"\nAttributeEnd\n"
      "AttributeBegin\nScale 2 2 2\nObjectInstance \"rock\"\nAttributeEnd\n"
      "WorldEnd\n",
      "read.rib", ".");
  ASSERT_EQ(r.scene.prototypes.size(), 1u);  // an object never placed is not a prototype
  ASSERT_EQ(r.scene.instances.size(), 2u);
  EXPECT_TRUE(r.scene.meshes.empty());
  const Instance& a = r.scene.instances[0];
  EXPECT_EQ(a.name, "first");
  EXPECT_EQ(a.double_sided, 0);
  EXPECT_TRUE(a.reverse_orientation);
  EXPECT_EQ(glm::vec3(a.object_to_world * glm::vec4(0, 0, 0, 1)), glm::vec3(5, 0, 0));
  EXPECT_EQ(r.scene.instances[1].double_sided, 1);
  EXPECT_FALSE(r.scene.instances[1].reverse_orientation);
  const Mesh& tri = r.scene.prototypes[0].meshes[0];
  EXPECT_EQ(glm::vec3(tri.object_to_world * glm::vec4(0, 0, 0, 1)), glm::vec3(0, 0, 1));
}

// --- validation -----------------------------------------------------------------------

void expect_refused(Scene s, const std::string& needle) {
  try {
    validate_scene(s);
    ADD_FAILURE() << "accepted; expected an error naming '" << needle << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(InstancesValidation, BadInstancesAreRefusedWithAMessage) {
  const Scene good = instanced_scene();
  validate_scene(good);
  Scene s = good;
  s.instances[1].prototype = 7;
  expect_refused(s, "places prototype 7 of 2");
  s = good;
  s.instances[2].object_to_world[3][0] = NAN;
  expect_refused(s, "instance '2': transform contains NaN");
  s = good;
  s.instances[0].object_to_world = glm::translate(glm::mat4(1.0f), {3e15f, 0.0f, 0.0f});
  expect_refused(s, "coordinates beyond 1e15");
  s = good;
  s.instances[3].material = 9;
  expect_refused(s, "material index 9 out of range");
  s = good;
  s.motion_steps = 2;
  s.instances[0].motion_object_to_world = {glm::mat4(1.0f)};
  expect_refused(s, "1 motion transforms for 2 motion steps");
  s = good;
  s.motion_steps = 2;
  s.prototypes[0].meshes[0].motion_object_to_world = {glm::mat4(1.0f), glm::mat4(1.0f)};
  expect_refused(s, "moves on its own");
  s = good;
  s.prototypes[0].meshes[0].face_vertex_indices[0] = 99;
  expect_refused(s, "body");
}

}  // namespace
}  // namespace mp::test
