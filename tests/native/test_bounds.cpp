// Bounds are conservative: every vertex the dicer produces for a sub-patch
// lies inside the bound that bound & split computed for it. Runs the same
// header code the kernels run (mp_bound.h, mp_patch_eval.h) on the host.
#include <gtest/gtest.h>

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <string>

#include "host_dicer.h"
#include "scene/curves.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

struct Checked {
  size_t diced = 0, vertices = 0, gregory = 0, ribbons = 0, violations = 0;
  std::string first_violation;
  // The net's plane (mp_net_plane, mp_plane_near_depth): points of
  // micropolygons nearer than its bound over the pixel they fall in, and
  // points where that bound exceeds the sub-patch's nearest depth by more
  // than a thousandth (where it culls what the nearest depth cannot).
  size_t plane_points = 0, plane_violations = 0, plane_tighter = 0;
  std::string first_plane_violation;
};

// Runs bound & split on the host and checks every diced grid vertex.
Checked check_scene(const Scene& scene) {
  Checked c;
  host_dice(scene, [&](const DicedGrid& g, const FrameParams& f, const PatchBuffer& patches) {
    const SubPatch& sp = g.sp;
    const glm::vec4* cp = patches.points.data() + size_t(sp.patch) * MP_PATCH_POINTS;
    const uint type = patches.info[sp.patch].x;
    c.gregory += type == MP_PATCH_GREGORY;
    float3 lo[16], hi[16];
    float u0 = std::min({sp.corner[0], sp.corner[2], sp.corner[4], sp.corner[6]});
    float u1 = std::max({sp.corner[0], sp.corner[2], sp.corner[4], sp.corner[6]});
    float v0 = std::min({sp.corner[1], sp.corner[3], sp.corner[5], sp.corner[7]});
    float v1 = std::max({sp.corner[1], sp.corner[3], sp.corner[5], sp.corner[7]});
    if (type == MP_PATCH_CURVE) {
      const MpPlacement none = mp_placement_none();
      mp_ribbon_hull(cp, &sp, &none, lo, hi);
    } else {
      mp_subpatch_net_boxes(cp, type, u0, v0, u1, v1, lo, hi);
    }
    c.ribbons += type == MP_PATCH_CURVE;
    MpBound bound = mp_bound_boxes(lo, hi, 16, f);
    glm::vec3 box_lo(3e38f), box_hi(-3e38f);
    for (int k = 0; k < 16; ++k) box_lo = glm::min(box_lo, lo[k]), box_hi = glm::max(box_hi, hi[k]);
    for (size_t k = 0; k < g.p.size(); ++k) {
      const glm::vec3 P = g.p[k];
      float tol = 1e-4f * (1.0f + glm::length(P));
      glm::vec2 r = mp_project(P, f);
      float rtol = 1e-3f * (1.0f + std::abs(r.x) + std::abs(r.y));
      float depth = -P.z;
      bool inside = depth >= bound.dmin - tol && depth <= bound.dmax + tol && r.x >= bound.xmin - rtol &&
                    r.x <= bound.xmax + rtol && r.y >= bound.ymin - rtol && r.y <= bound.ymax + rtol;
      for (int a = 0; a < 3; ++a) inside = inside && P[a] >= box_lo[a] - tol && P[a] <= box_hi[a] + tol;
      if (!inside && c.violations++ == 0)
        c.first_violation = "patch " + std::to_string(sp.patch) + " type " + std::to_string(type) + " at (" +
                            std::to_string(g.uv[k].x) + ", " + std::to_string(g.uv[k].y) + ")";
      ++c.vertices;
    }
    // Points of every micropolygon (corners, edge middles, centre: convex
    // combinations of its vertices, as the rasteriser's samples are) keep
    // to the plane's depth bound over the pixel they project into.
    const float4 plane = mp_net_plane(lo, hi, 16, f);
    const bool straddles = !f.ortho && bound.dmin <= f.eye_epsilon;
    if (!straddles && (plane.x != 0.0f || plane.y != 0.0f || plane.z != 0.0f))
      for (const auto& poly : g.polygons) {
        const glm::vec3 a = g.slot_p[poly[0]], b = g.slot_p[poly[1]], cc = g.slot_p[poly[2]], d = g.slot_p[poly[3]];
        for (const glm::vec3& P : {a, b, cc, d, 0.5f * (a + b), 0.5f * (b + cc), 0.5f * (a + cc),
                                   0.25f * (a + b + cc + d), (a + 2.0f * b + cc) * 0.25f}) {
          const glm::vec2 r = mp_project(P, f);
          if (!(std::abs(r.x) < 1e6f && std::abs(r.y) < 1e6f)) continue;
          const float x0 = std::floor(r.x), y0 = std::floor(r.y);
          const float near = mp_plane_near_depth(plane, f, x0, y0, x0 + 1.0f, y0 + 1.0f);
          const float depth = -P.z;
          ++c.plane_points;
          if (near > 1.001f * bound.dmin) ++c.plane_tighter;
          if (depth < near * (1.0f - 1.0f / 4096.0f) && c.plane_violations++ == 0)
            c.first_plane_violation = "patch " + std::to_string(sp.patch) + ": depth " + std::to_string(depth) +
                                      " nearer than the plane's bound " + std::to_string(near);
        }
      }
    ++c.diced;
  });
  return c;
}

// An orthographic camera from (3, 2, 4) at the origin over the window
// [-w, w] x [-h, h].
void view_orthographically(Scene& s, float w, float h) {
  s.camera = look_at({3.0f, 2.0f, 4.0f}, {0, 0, 0});
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.screen_left = -w, s.camera.screen_right = w, s.camera.screen_bottom = -h, s.camera.screen_top = h;
}

TEST(Bounds, DicedVerticesLieInsideTheirSubPatchBounds) {
  Scene s = base_scene(640, 480, 1);
  s.camera = look_at({2.0f, 1.5f, 3.0f}, {0, 0, 0}, 50.0f);
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  Mesh wavy = grid_mesh(6, 2.0f, SubdivScheme::CatmullClark);
  for (auto& p : wavy.points) p.z = 0.4f * std::sin(3.0f * p.x) * std::cos(2.0f * p.y) - 1.5f;
  s.meshes.push_back(wavy);
  Mesh flat = grid_mesh(3, 2.0f, SubdivScheme::None);
  flat.object_to_world = glm::rotate(glm::mat4(1), 0.7f, glm::vec3(1, 1, 0));
  s.meshes.push_back(flat);
  Checked c = check_scene(s);
  EXPECT_EQ(c.violations, 0u) << c.first_violation;
  EXPECT_EQ(c.plane_violations, 0u) << c.first_plane_violation;
  // Most points of a sub-patch lie deeper than its nearest (89% here).
  EXPECT_GT(c.plane_tighter, c.plane_points / 2) << "the plane's bound seldom tells more than the nearest depth";
  EXPECT_GT(c.diced, 100u);
  EXPECT_GT(c.gregory, 10u);  // Gregory patches around the cube's corners
  EXPECT_GT(c.vertices, 10000u);
}

TEST(Bounds, OrthographicAndNearCameraBoundsAreConservative) {
  Scene s = base_scene(320, 240, 1);
  s.camera = look_at({0.3f, 0.2f, 1.4f}, {0, 0, 0}, 70.0f);  // close: patches straddle the near region
  s.meshes.push_back(cube_mesh(SubdivScheme::CatmullClark));
  Checked near = check_scene(s);
  EXPECT_EQ(near.violations, 0u) << near.first_violation;
  EXPECT_EQ(near.plane_violations, 0u) << near.first_plane_violation;
  EXPECT_GT(near.diced, 50u);
  view_orthographically(s, 2.5f, 2.0f);
  Checked ortho = check_scene(s);
  EXPECT_EQ(ortho.violations, 0u) << ortho.first_violation;
  EXPECT_EQ(ortho.plane_violations, 0u) << ortho.first_plane_violation;
  EXPECT_GT(ortho.plane_tighter, ortho.plane_points / 4);  // 65% here
  EXPECT_GT(ortho.diced, 50u);
}

// Ribbons (mp_ribbon.h) turn to face the eye: their bound is their centre
// net grown by the radius, which holds them from any view. Strands of
// changing radius bend about the camera, some near enough to straddle the
// eye plane and some seen end on.
TEST(Bounds, RibbonsStayInsideTheirBoundsFromAnyView) {
  Scene s = base_scene(320, 240, 1);
  s.camera = look_at({0.2f, 0.3f, 2.0f}, {0, 0, 0}, 60.0f);
  CurveSet curves;
  curves.name = "strands";
  curves.ribbons = true;
  for (int c = 0; c < 24; ++c) {
    curves.offsets.push_back(int(curves.points.size()));
    const float a = 0.26f * float(c);
    for (int k = 0; k < 6; ++k) {
      const float t = float(k) / 5.0f;
      curves.points.emplace_back(std::cos(a) * (0.3f + t), std::sin(a) * (0.3f + t) + 0.2f * std::sin(5.0f * t),
                                 1.9f * t - 1.0f + 0.1f * float(c % 3));
      curves.radii.push_back(0.004f + 0.05f * t * (1.0f - t) * float(c % 4));
    }
  }
  curves.offsets.push_back(int(curves.points.size()));
  ASSERT_EQ(add_curves(s, curves), 0u);
  Checked c = check_scene(s);
  EXPECT_EQ(c.violations, 0u) << c.first_violation;
  EXPECT_EQ(c.ribbons, c.diced);
  EXPECT_GT(c.diced, 100u);
  view_orthographically(s, 2.0f, 1.5f);
  Checked ortho = check_scene(s);
  EXPECT_EQ(ortho.violations, 0u) << ortho.first_violation;
  EXPECT_GT(ortho.diced, 24u);
}

TEST(Bounds, APlaneCullsALayerTheNearestDepthCannot) {
  // A 64 x 64 view (raster = 64 x / d + 32) over two tilted planes, depth
  // d = c / (1 - v / 2) along the ray of slope v, c = 2 for the top layer
  // and 2.5 below it. The pyramid (cells of 4 pixels, three levels) holds
  // the top layer's farthest depth per cell. A sub-patch of the lower layer
  // filling the view has its nearest depth (2.0) in front of the top's
  // farthest in the far cells (2.67), so that bound alone keeps it; its
  // plane's depth in each cell lies behind the top's there, so with the
  // plane it is culled. A layer 2 % below the top is kept either way.
  FrameParams f{};
  f.width = f.height = 64;
  f.ax = f.ay = 64.0f, f.bx = f.by = 32.0f;
  f.view_kind = MP_VIEW_CAMERA;
  f.eye_epsilon = 1e-4f;
  OcclusionParams o{};
  o.levels = 3, o.cell_shift = 2, o.base_w = o.base_h = 16;
  std::vector<uint> pyramid(mp_occlusion_cells(o));
  for (int k = 0; k < o.levels; ++k) {
    const int side = mp_occlusion_side(16, k), cell = 4 << k;
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) {
        const float v_far = (float((y + 1) * cell) - f.by) / f.ay;  // the depth grows with v
        pyramid[mp_occlusion_offset(o, k) + uint(y * side + x)] = as_uint(2.0f / (1.0f - 0.5f * v_far));
      }
  }
  auto layer = [&](float c, float3* lo, float3* hi) {
    // A 4 x 4 net over the view: points of the plane through the rays at
    // the view's corners, spread bilinearly (a plane's bilinear patch).
    auto at = [&](float u, float v) { const float d = c / (1.0f - 0.5f * v); return glm::vec3(u * d, v * d, -d); };
    const glm::vec3 p00 = at(-0.5f, -0.5f), p10 = at(0.5f, -0.5f), p01 = at(-0.5f, 0.5f), p11 = at(0.5f, 0.5f);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        const float s = float(i) / 3.0f, t = float(j) / 3.0f;
        lo[4 * j + i] = hi[4 * j + i] = (1 - t) * ((1 - s) * p00 + s * p10) + t * ((1 - s) * p01 + s * p11);
      }
  };
  const float4 none(0.0f);
  for (const float c : {2.5f, 2.04f}) {
    float3 lo[16], hi[16];
    layer(c, lo, hi);
    const MpBound b = mp_bound_boxes(lo, hi, 16, f);
    const float4 plane = mp_net_plane(lo, hi, 16, f);
    EXPECT_NEAR(b.dmin, c / 1.25f, 1e-4f);
    EXPECT_FALSE(mp_occluded(pyramid.data(), o, f, b.xmin, b.ymin, b.xmax, b.ymax, b.dmin, none)) << c;
    EXPECT_EQ(mp_occluded(pyramid.data(), o, f, b.xmin, b.ymin, b.xmax, b.ymax, b.dmin, plane), c > 2.2f) << c;
  }
}

}  // namespace
}  // namespace mp::test
