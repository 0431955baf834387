// Bounds are conservative: every vertex the dicer produces for a sub-patch
// lies inside the bound that bound & split computed for it. Runs the same
// header code the kernels run (mp_bound.h, mp_patch_eval.h) on the host.
#include <gtest/gtest.h>

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <string>

#include "host_dicer.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

struct Checked {
  size_t diced = 0, vertices = 0, gregory = 0, violations = 0;
  std::string first_violation;
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
    mp_subpatch_net_boxes(cp, type, u0, v0, u1, v1, lo, hi);
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
    ++c.diced;
  });
  return c;
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
  EXPECT_GT(near.diced, 50u);
  s.camera = look_at({3.0f, 2.0f, 4.0f}, {0, 0, 0});
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.screen_left = -2.5f, s.camera.screen_right = 2.5f, s.camera.screen_bottom = -2.0f, s.camera.screen_top = 2.0f;
  Checked ortho = check_scene(s);
  EXPECT_EQ(ortho.violations, 0u) << ortho.first_violation;
  EXPECT_GT(ortho.diced, 50u);
}

}  // namespace
}  // namespace mp::test
