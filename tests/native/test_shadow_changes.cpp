// Which kept shadow pages a changed surface reaches (shadow_changes.h,
// shadow_page_touches in shadow_layout.h): host logic, no device. The
// renders that prove kept pages equal rendered ones are in test_shadows.cpp
// (PagesOutsideAChangedSurfaceAreKept).
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/shadows/shadow_changes.h"
#include "shadow/mp_shadow.h"
#include "scene_fixtures.h"

namespace mp {
namespace {

using test::polygon;

Mesh square(float x, float y, float z, float half) {
  return polygon({{x - half, y - half, z}, {x + half, y - half, z}, {x + half, y + half, z}, {x - half, y + half, z}});
}

ShadowCasters casters(const Scene& s) { return shadow_casters(s, shadow_geometry_keys(s)); }

Scene two_squares() {
  Scene s;
  s.materials.push_back(Material{});
  s.meshes.push_back(square(-5, 0, 1, 1));
  s.meshes.push_back(square(5, 0, 1, 1));
  return s;
}

TEST(ShadowChanges, SameSurfacesInAnyOrderChangeNothing) {
  Scene a = two_squares(), b = a;
  std::swap(b.meshes[0], b.meshes[1]);
  b.meshes[0].name = "renamed";
  b.meshes[1].visible_camera = false;
  const auto boxes = shadow_changes(casters(a), casters(b));
  ASSERT_TRUE(boxes.has_value());
  EXPECT_TRUE(boxes->empty());
}

TEST(ShadowChanges, AMovedSurfaceGivesWhereItWasAndWhereItIs) {
  Scene a = two_squares(), b = a;
  b.meshes[1].object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0, 3, 0));
  const auto boxes = shadow_changes(casters(a), casters(b));
  ASSERT_TRUE(boxes.has_value());
  ASSERT_EQ(boxes->size(), 2u);
  bool was = false, is = false;
  for (const WorldBounds& box : *boxes) {
    EXPECT_LE(box.lo.x, 4.0f);
    EXPECT_GE(box.hi.x, 6.0f);
    was = was || (box.lo.y <= -1.0f && box.hi.y >= 1.0f && box.hi.y < 2.0f);
    is = is || (box.lo.y <= 2.0f && box.lo.y > 1.0f && box.hi.y >= 4.0f);
  }
  EXPECT_TRUE(was && is);
}

TEST(ShadowChanges, SurfacesThatCastNoShadowDoNotCount) {
  Scene a = two_squares(), b = a;
  a.meshes[1].cast_shadows = b.meshes[1].cast_shadows = false;
  b.meshes[1].object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0, 3, 0));
  const auto boxes = shadow_changes(casters(a), casters(b));
  ASSERT_TRUE(boxes.has_value());
  EXPECT_TRUE(boxes->empty());
  // Casting again: it appears where it is.
  b.meshes[1].cast_shadows = true;
  const auto appeared = shadow_changes(casters(a), casters(b));
  ASSERT_TRUE(appeared.has_value());
  EXPECT_EQ(appeared->size(), 1u);
}

TEST(ShadowChanges, WhatCannotBeBoundedChangesEverything) {
  Scene a = two_squares();
  // A transform over the shutter.
  Scene moving = a;
  moving.motion_steps = 2;
  moving.meshes[1].motion_object_to_world = {glm::mat4(1.0f), glm::rotate(glm::mat4(1.0f), 1.0f, glm::vec3(0, 0, 1))};
  EXPECT_FALSE(shadow_changes(casters(a), casters(moving)).has_value());
  // More surfaces changed than are told apart.
  Scene many = a;
  for (size_t i = 0; i <= kMaxShadowChanges; ++i) many.meshes.push_back(square(float(i), 10, 1, 0.5f));
  EXPECT_FALSE(shadow_changes(casters(a), casters(many)).has_value());
  // An image that a displacing program may read.
  Scene displaced = a;
  displaced.material_programs.push_back({"lift", "float3 mp_node_displacement(const MpNodeGlobals* g) "
                                                 "{ return (float3)(0.0f); }\n"});
  displaced.materials[0].program = 0;
  displaced.materials[0].program_displaces = true;
  displaced.images.push_back(Image{});
  Scene repainted = displaced;
  repainted.images[0].pixels = {glm::vec4(1.0f, 0.0f, 0.0f, 1.0f)};
  repainted.images[0].width = repainted.images[0].height = 1;
  EXPECT_FALSE(shadow_changes(casters(displaced), casters(repainted)).has_value());
  // The first frame: nothing to compare with.
  EXPECT_FALSE(shadow_changes(ShadowCasters{}, casters(a)).has_value());
}

TEST(ShadowPageTouches, ASunsPagesUnderTheBoxAndNoOthers) {
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::vec3(0, 0, -1);  // light space: x and y as the world's, up to signs
  WorldBounds box;
  box.lo = glm::vec3(10.0f, 10.0f, 0.0f);
  box.hi = glm::vec3(11.0f, 11.0f, 1.0f);
  // Level 0: texels of one unit, pages of 128. The box lies in one page
  // per axis, and its neighbours lie within the margin only at the edges.
  int touched = 0;
  for (int y = -3; y <= 3; ++y)
    for (int x = -3; x <= 3; ++x) touched += shadow_page_touches(sun, 0, x, y, box);
  EXPECT_GE(touched, 1);
  EXPECT_LE(touched, 4);
  EXPECT_FALSE(shadow_page_touches(sun, 0, 5, 5, box));
  // A level whose page is a thousandth of a unit: the box spans about a
  // thousand pages per axis around 10 / 0.128 = 78.
  const int level = -7;  // texel 1/128: page of one unit
  int finer = 0;
  for (int y = -20; y <= 20; ++y)
    for (int x = -20; x <= 20; ++x) finer += shadow_page_touches(sun, level, x, y, box);
  int at_box = 0;
  for (int y = -13; y <= 13; ++y)
    for (int x = -13; x <= 13; ++x) at_box += shadow_page_touches(sun, level, x, y, box);
  EXPECT_EQ(finer, at_box);  // none far from the box
  EXPECT_GE(at_box, 1);
}

TEST(ShadowPageTouches, ACubesFaceTowardTheBoxAndNotTheOpposite) {
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.position = glm::vec3(0.0f);
  WorldBounds box;
  box.lo = glm::vec3(4.0f, -0.5f, -0.5f);
  box.hi = glm::vec3(5.0f, 0.5f, 0.5f);
  // Light space is the world's for a point lamp; the box lies on +X
  // (face 0) around its centre, away from every other face.
  const int mip = 3, side = MP_MAP_PAGES >> mip;
  int on_face = 0, elsewhere = 0;
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) {
        const bool t = shadow_page_touches(lamp, face * MP_CUBE_MIPS + mip, x, y, box);
        (face == 0 ? on_face : elsewhere) += t;
        if (face == 0 && t) {
          // Pages near the face's centre only (the box spans about 0.25 of
          // the face's half-width).
          EXPECT_NEAR(x + 0.5, side / 2.0, side * 0.2);
          EXPECT_NEAR(y + 0.5, side / 2.0, side * 0.2);
        }
      }
  EXPECT_GT(on_face, 0);
  EXPECT_EQ(elsewhere, 0);
}

}  // namespace
}  // namespace mp
