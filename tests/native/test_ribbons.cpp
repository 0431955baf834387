// Ribbons (kernels/geometry/mp_ribbon.h): a strand segment drawn as a strip
// that faces each view. Its geometry against the tube it stands for (width,
// facing, the round normal), the eye each kind of view gives it, and
// renders against round tubes and flat rectangles of the same size.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "renderer_fixture.h"
#include "scene/curves.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// A ribbon patch's 20 device points from a segment (its 16, then partners
// the kernels under test do not read).
std::array<glm::vec4, MP_PATCH_POINTS> ribbon_patch(const CurveSegment& s) {
  std::vector<glm::vec3> pts;
  add_ribbon(s, pts);
  std::array<glm::vec4, MP_PATCH_POINTS> cp{};
  for (int k = 0; k < 16; ++k) cp[size_t(k)] = glm::vec4(pts[size_t(k)], 0.0f);
  return cp;
}

glm::dvec3 bezier(const glm::dvec3* p, double t) {
  const double s = 1.0 - t;
  return s * s * s * p[0] + 3.0 * t * s * s * p[1] + 3.0 * t * t * s * p[2] + t * t * t * p[3];
}

double bezier(const double* r, double t) {
  const double s = 1.0 - t;
  return s * s * s * r[0] + 3.0 * t * s * s * r[1] + 3.0 * t * t * s * r[2] + t * t * t * r[3];
}

TEST(Ribbons, FaceTheEyeAtTheTubesWidthWithItsNormal) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> any(-1.0, 1.0);
  const CurveSegment seg{{{0, 0, -3}, {0.4, 0.3, -3.2}, {0.8, -0.2, -2.9}, {1.2, 0.1, -3.1}}, {0.05, 0.04, 0.03, 0.01}};
  const auto cp = ribbon_patch(seg);
  // Placed as an instance would be: turned, moved, scaled by 2.
  const glm::mat4 m = glm::scale(glm::rotate(glm::translate(glm::mat4(1), glm::vec3(0.3f, -0.2f, 0.5f)), 0.6f,
                                             glm::normalize(glm::vec3(1, 2, 3))),
                                 glm::vec3(2.0f));
  float rows[12], normal_rows[12];
  const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(m)));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      rows[4 * r + c] = m[c][r];
      normal_rows[4 * r + c] = c < 3 ? nm[c][r] : 0.0f;
    }
  for (int placed = 0; placed < 2; ++placed) {
    MpPlacement place = placed ? mp_placement_rows(rows, normal_rows) : mp_placement_none();
    const double scale = placed ? 2.0 : 1.0;
    for (int trial = 0; trial < 40; ++trial) {
      const bool ortho = trial % 4 == 3;
      const glm::dvec3 e(any(rng) * 4.0, any(rng) * 4.0, 2.0 + any(rng));
      place.eye = ortho ? glm::vec4(glm::normalize(glm::vec3(e)), 0.0f) : glm::vec4(glm::vec3(e), 1.0f);
      const double v = (trial + 0.5) / 40.0;
      float3 P[3], du, dv, N[3];
      for (int k = 0; k < 3; ++k) mp_eval_ribbon(cp.data(), 0.5f * float(k), float(v), &place, &P[k], &du, &dv, &N[k]);
      glm::dvec3 c = bezier(seg.p, v);
      if (placed) c = glm::dvec3(m * glm::vec4(glm::vec3(c), 1.0f));
      const double r = bezier(seg.r, v) * scale;
      const glm::dvec3 side = glm::dvec3(P[2]) - glm::dvec3(P[0]);
      const glm::dvec3 t = glm::normalize(glm::dvec3(dv));
      const glm::dvec3 w = ortho ? glm::dvec3(glm::vec3(place.eye)) : glm::normalize(e - c);
      EXPECT_NEAR(glm::length(glm::dvec3(P[1]) - c), 0.0, 1e-5) << trial;  // the middle is on the centre line
      EXPECT_NEAR(glm::length(side), 2.0 * r, 1e-5) << trial;              // as wide as the tube
      EXPECT_NEAR(glm::dot(side, t), 0.0, 1e-5) << trial;                  // across the strand
      EXPECT_NEAR(glm::dot(side, w), 0.0, 1e-5) << trial;                  // square to the eye
      EXPECT_NEAR(glm::length(glm::dvec3(du)), 2.0 * r, 1e-5) << trial;
      // The tube's normal at each offset h: the sides, and the eye between.
      const glm::dvec3 s = glm::normalize(side), f = glm::normalize(w - glm::dot(w, t) * t);
      for (int k = 0; k < 3; ++k) {
        const double h = double(k) - 1.0;
        const glm::dvec3 want = h * s + std::sqrt(1.0 - h * h) * f;
        EXPECT_NEAR(glm::length(glm::dvec3(N[k]) - want), 0.0, 1e-4) << trial << " h " << h;
      }
    }
  }
}

TEST(Ribbons, EachViewGivesItsOwnEye) {
  // A light's view: camera space -> its space by a rigid transform looking
  // from `from` at the origin.
  const glm::vec3 from(2.0f, -1.0f, 3.0f);
  const glm::mat4 view = glm::lookAt(from, glm::vec3(0.0f), glm::vec3(0, 0, 1));
  FrameParams f{};
  f.has_view = 1;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) f.view[4 * r + c] = view[c][r];
  MpPlacement place = mp_placement_none();
  EXPECT_EQ(place.eye.w, 1.0f);  // the camera's own eye, at its origin
  EXPECT_EQ(glm::length(glm::vec3(place.eye)), 0.0f);
  mp_place_facing(&place, f);
  EXPECT_EQ(place.eye.w, 1.0f);
  EXPECT_NEAR(glm::length(glm::vec3(place.eye) - from), 0.0f, 1e-5f);
  f.ortho = 1;  // a sun's view: the direction towards it
  mp_place_facing(&place, f);
  EXPECT_EQ(place.eye.w, 0.0f);
  EXPECT_NEAR(glm::length(glm::vec3(place.eye) - glm::normalize(from)), 0.0f, 1e-5f);
  f.has_view = 0;  // the camera's orthographic view: +z
  mp_place_facing(&place, f);
  EXPECT_EQ(glm::vec3(place.eye), glm::vec3(0, 0, 1));
  EXPECT_EQ(place.push, 0.0f);
  // A light's view moves the strip a radius away from the light, so the
  // camera's strip of the same strand lies wholly in front of it.
  f.view_kind = MP_VIEW_SHADOW;
  f.has_view = 1;
  f.ortho = 0;
  mp_place_facing(&place, f);
  EXPECT_EQ(place.push, 1.0f);
  const CurveSegment seg{{{0, 0, 0}, {0.3, 0.1, 0}, {0.6, -0.1, 0.1}, {1, 0, 0}}, {0.1, 0.1, 0.1, 0.1}};
  const auto cp = ribbon_patch(seg);
  MpPlacement camera = mp_placement_none();
  const glm::vec3 to_light = glm::normalize(from - glm::vec3(0.5f, 0.0f, 0.0f));
  for (float v : {0.25f, 0.5f, 0.75f}) {
    float3 lp, cpnt, du, dv, n;
    mp_eval_ribbon(cp.data(), 0.5f, v, &place, &lp, &du, &dv, &n);
    float3 centre = glm::vec3(bezier(seg.p, v));
    EXPECT_NEAR(glm::length(glm::vec3(lp) - centre), 0.1f, 1e-5f);  // a radius off the centre line
    const float behind = glm::dot(glm::vec3(lp), to_light);
    for (float u : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
      mp_eval_ribbon(cp.data(), u, v, &camera, &cpnt, &du, &dv, &n);
      EXPECT_GT(glm::dot(glm::vec3(cpnt), to_light), behind - 1e-3f) << u << " " << v;
    }
  }
}

class RibbonRenderTest : public SharedRendererTest {};

// Strands across the view, curved and tapered, under a perspective camera:
// ribbons cover what the round tubes of the same curves cover (the tubes'
// silhouette is as wide; only the open ends differ), and a straight ribbon
// square to the view covers what the rectangle it lies on covers.
TEST_F(RibbonRenderTest, CoversWhatTheTubeAndTheRectangleCover) {
  Scene s = base_scene(320, 240, 16);
  s.camera = look_at({0.0f, 0.0f, 4.0f}, {0, 0, 0}, 50.0f);
  CurveSet curves;
  curves.name = "strands";
  for (int c = 0; c < 6; ++c) {
    curves.offsets.push_back(int(curves.points.size()));
    for (int k = 0; k < 7; ++k) {
      const float t = float(k) / 6.0f;
      curves.points.emplace_back(2.6f * t - 1.3f, 0.35f * float(c) - 0.9f + 0.15f * std::sin(7.0f * t + float(c)),
                                 0.8f * std::cos(4.0f * t) - 0.4f);
      curves.radii.push_back(0.02f + 0.015f * (1.0f - t));
    }
  }
  curves.offsets.push_back(int(curves.points.size()));
  double area[2];
  for (int ribbons = 0; ribbons < 2; ++ribbons) {
    Scene t = s;
    curves.ribbons = ribbons == 1;
    ASSERT_EQ(add_curves(t, curves), 0u);
    EXPECT_EQ(t.bezier_patches[0].ribbons, ribbons == 1);
    area[ribbons] = coverage(renderer_->render(t));
  }
  EXPECT_GT(area[0], 2000.0);
  EXPECT_NEAR(area[1] / area[0], 1.0, 0.015) << area[1] << " against tubes' " << area[0];

  // Straight along x at depth 4 (z = 0): the strip [-1.2, 1.2] x [-0.05, 0.05].
  CurveSet straight;
  straight.name = "straight";
  straight.ribbons = true;
  straight.points = {{-1.2f, 0, 0}, {0, 0, 0}, {1.2f, 0, 0}};
  straight.radii = {0.05f, 0.05f, 0.05f};
  straight.offsets = {0, 3};
  Scene a = s, b = s;
  ASSERT_EQ(add_curves(a, straight), 0u);
  b.meshes.push_back(polygon({{-1.2f, -0.05f, 0}, {1.2f, -0.05f, 0}, {1.2f, 0.05f, 0}, {-1.2f, 0.05f, 0}}));
  const double ribbon = coverage(renderer_->render(a)), rectangle = coverage(renderer_->render(b));
  EXPECT_GT(rectangle, 500.0);
  EXPECT_NEAR(ribbon / rectangle, 1.0, 0.005) << ribbon << " against " << rectangle;
}

// Ribbons placed by instances (fur on scattered creatures) face the view
// as their copies placed by hand do, shadows included.
TEST_F(RibbonRenderTest, InstancesRenderLikeTheirCopies) {
  Scene s = base_scene(160, 120, 4);
  s.camera = look_at({0.0f, -4.0f, 2.0f}, {0, 0, 0}, 50.0f);
  s.meshes.push_back(polygon({{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}}));  // a floor to shadow
  CurveSet fur;
  fur.name = "fur";
  fur.ribbons = true;
  for (int c = 0; c < 30; ++c) {
    fur.offsets.push_back(int(fur.points.size()));
    const float a = 0.7f * float(c), r0 = 0.05f * float(c % 6);
    for (int k = 0; k < 5; ++k) {
      const float t = float(k) / 4.0f;
      fur.points.emplace_back(r0 * std::cos(a) + 0.2f * t * t, r0 * std::sin(a), 0.6f * t);
      fur.radii.push_back(0.012f * (1.0f - 0.7f * t));
    }
  }
  fur.offsets.push_back(int(fur.points.size()));
  const glm::mat4 placements[3] = {
      glm::translate(glm::mat4(1), glm::vec3(-1.2f, 0.0f, 0.0f)),
      glm::rotate(glm::translate(glm::mat4(1), glm::vec3(0.0f, 0.5f, 0.0f)), 1.1f, glm::vec3(0, 0, 1)),
      glm::scale(glm::rotate(glm::translate(glm::mat4(1), glm::vec3(1.2f, 0.0f, 0.0f)), -0.7f, glm::vec3(0, 0, 1)),
                 glm::vec3(1.5f))};
  Scene copies = s, instanced = s;
  for (const glm::mat4& m : placements) {
    CurveSet c = fur;
    c.object_to_world = m;
    ASSERT_EQ(add_curves(copies, c), 0u);
  }
  Scene shape;
  ASSERT_EQ(add_curves(shape, fur), 0u);
  instanced.prototypes.push_back(Prototype{"fur", {}, {shape.bezier_patches[0]}});
  for (const glm::mat4& m : placements) {
    Instance inst;
    inst.object_to_world = m;
    instanced.instances.push_back(inst);
  }
  const RenderResult a = renderer_->render(copies), b = renderer_->render(instanced);
  double diff = 0.0, total = 0.0;
  for (size_t i = 0; i < a.rgba.size(); ++i) diff += std::fabs(a.rgba[i] - b.rgba[i]), total += a.rgba[i];
  EXPECT_GT(total, 1000.0);
  EXPECT_LT(diff / total, 2e-3) << diff << " of " << total;
}

// A strand's ribbons are one patch a segment; its tubes four a quarter turn
// each, more where the strand bends.
TEST(Ribbons, OnePatchASegment) {
  Scene s;
  CurveSet curves;
  curves.name = "bent";
  curves.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 1}};
  curves.radii = {0.1f, 0.1f, 0.1f, 0.0f};
  curves.offsets = {0, 4};
  curves.point_layers = {{{0, 0}, {1, 0}, {2, 0}, {3, 0}}};
  curves.ribbons = true;
  ASSERT_EQ(add_curves(s, curves), 0u);
  const BezierPatches& set = s.bezier_patches[0];
  EXPECT_TRUE(set.ribbons);
  EXPECT_FALSE(set.round_u);
  ASSERT_EQ(set.control_points.size(), 3u * 16u);
  // Corner values: u across (both sides alike), v along the segment.
  for (int p = 0; p < 3; ++p)
    EXPECT_EQ((std::vector<glm::vec2>(set.uv_layers[0].begin() + 4 * p, set.uv_layers[0].begin() + 4 * p + 4)),
              (std::vector<glm::vec2>{{float(p), 0}, {float(p), 0}, {float(p + 1), 0}, {float(p + 1), 0}}));
  // Row j: the centre point, then the three radius points.
  for (int p = 0; p < 3; ++p)
    for (int j = 0; j < 4; ++j) {
      const glm::vec3 c = set.control_points[16 * p + 4 * j];
      const float r = glm::length(set.control_points[16 * p + 4 * j + 1] - c);
      EXPECT_NEAR(glm::length(set.control_points[16 * p + 4 * j + 2] - c), r, 1e-6f);
      EXPECT_NEAR(glm::length(set.control_points[16 * p + 4 * j + 3] - c), r, 1e-6f);
    }
  Scene tubes;
  curves.ribbons = false;
  ASSERT_EQ(add_curves(tubes, curves), 0u);
  EXPECT_GE(tubes.bezier_patches[0].control_points.size(), 3u * size_t(kTubePatchesPerSegment) * 16u);
}

}  // namespace
}  // namespace mp::test
