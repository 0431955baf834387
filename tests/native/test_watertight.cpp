// Watertight dicing of closed surfaces.
//
//  - Exact: on the host, every grid edge segment the dicer produces inside the
//    frame is met by the bit-identical segment of exactly one other grid.
//  - Rendered: from 50 seeded views per object (far, near and close-ups that
//    split neighbouring sub-patches to very different depths), single-sided
//    surfaces at 16 samples per pixel leave no pixel inside the silhouette
//    with alpha below 1 (a crack shows the background through).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <queue>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "host_dicer.h"
#include "stages/mp_blur.h"
#include "pipeline/frame/frame_params.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

struct Closed {
  std::string name;
  Mesh mesh;
  float radius;  // bounding sphere about the origin
};

std::vector<Closed> closed_surfaces() {
  Mesh torus = torus_mesh(12, 8, 0.45f, SubdivScheme::CatmullClark);
  Mesh creased = cube_mesh(SubdivScheme::CatmullClark);
  // A semi-sharp crease isolates deeper: more levels of transition patches.
  creased.crease_vertices = {0, 1, 1, 2};
  creased.crease_sharpness = {2.5f, 1.5f};
  return {{"catmull-clark cube", cube_mesh(SubdivScheme::CatmullClark), 1.2f},
          {"creased cube", creased, 1.6f},
          {"torus with extraordinary vertices", torus, 1.5f},
          {"polygon sphere", uv_sphere_mesh(14, 20), 1.0f}};
}

// View k of a seeded sequence: far views of the whole object, nearer ones and
// close-ups aimed at a point near the surface.
Camera seeded_view(std::mt19937& rng, float radius) {
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), t01(0.0f, 1.0f);
  glm::vec3 dir;
  do dir = glm::vec3(unit(rng), unit(rng), unit(rng));
  while (glm::length(dir) < 0.2f || glm::length(dir) > 1.0f);
  dir = glm::normalize(dir);
  const float near_or_far = t01(rng);
  const float distance = radius * (near_or_far < 0.4f ? 1.6f + 0.6f * t01(rng) : 2.2f + 4.0f * t01(rng));
  glm::vec3 target = near_or_far < 0.4f ? 0.7f * radius * glm::normalize(dir + 0.5f * glm::vec3(unit(rng), unit(rng), unit(rng)))
                                        : glm::vec3(0.0f);
  Camera c = look_at(dir * distance, target, 30.0f + 30.0f * t01(rng));
  c.clip_near = 0.001f;
  return c;
}

Scene view_scene(const Closed& object, const Camera& camera, int w, int h) {
  Scene s = base_scene(w, h, 16);
  s.camera = camera;
  s.settings.depth_and_normal_passes = true;
  Mesh m = object.mesh;
  m.double_sided = false;
  s.meshes.push_back(m);
  return s;
}

using Key = std::tuple<uint32_t, uint32_t, uint32_t>;
Key bits(const glm::vec3& p) {
  uint32_t b[3];
  std::memcpy(b, &p, sizeof b);
  return {b[0], b[1], b[2]};
}

// Micropolygon edges whose ends both lie inside the frame, with how many
// micropolygons use each (undirected, bit-exact end points, collapsed sides
// skipped, as are micropolygons collapsed to a line). On a closed surface every one must be used exactly twice: inside
// a grid by its two micropolygons (interior and stitching strips alike), on a
// grid's border by one micropolygon of each grid sharing that edge.
size_t count_unmatched_segments(const Scene& scene, size_t* checked) {
  std::map<std::pair<Key, Key>, int> segments;
  host_dice(scene, [&](const DicedGrid& g, const FrameParams& f, const PatchBuffer&) {
    auto inside = [&](const glm::vec3& p) {
      if (-p.z <= scene.camera.clip_near) return false;
      glm::vec2 r = mp_project(p, f);
      return r.x >= 0 && r.y >= 0 && r.x <= float(f.width) && r.y <= float(f.height);
    };
    for (const auto& q : g.polygons) {
      std::vector<glm::vec3> ring;
      for (uint s : q)
        if (ring.empty() || bits(ring.back()) != bits(g.slot_p[s])) ring.push_back(g.slot_p[s]);
      if (ring.size() > 1 && bits(ring.back()) == bits(ring.front())) ring.pop_back();
      if (ring.size() < 3) continue;
      for (size_t k = 0; k < ring.size(); ++k) {
        const glm::vec3 &a = ring[k], &b = ring[(k + 1) % ring.size()];
        if (!inside(a) || !inside(b)) continue;
        Key ka = bits(a), kb = bits(b);
        ++segments[ka < kb ? std::make_pair(ka, kb) : std::make_pair(kb, ka)];
      }
    }
  });
  size_t unmatched = 0;
  for (const auto& [segment, n] : segments) unmatched += n != 2;
  *checked = segments.size();
  return unmatched;
}

TEST(Watertight, EverySharedGridEdgeMatchesBitForBit) {
  std::mt19937 rng(20261121);
  for (const Closed& object : closed_surfaces())
    for (int view = 0; view < 12; ++view) {
      Scene s = view_scene(object, seeded_view(rng, object.radius), 320, 240);
      size_t checked = 0;
      size_t unmatched = count_unmatched_segments(s, &checked);
      EXPECT_EQ(unmatched, 0u) << object.name << ", view " << view << " of seed 20261121: " << unmatched << " of "
                               << checked << " segments unmatched";
      if (view == 0) EXPECT_GT(checked, 1000u) << object.name;
    }
}

// Pixels inside the silhouette with alpha below 1. Pixels not fully covered
// form connected regions; a region is outside the silhouette if it reaches
// the frame's edge (within 2 pixels: what lies beyond is unseen), holds a
// large uncovered area (background, a torus' hole), or is seen past a
// silhouette: the covered pixels around it lie at depths more than 10% apart
// (the torus' hole seen almost edge-on), where around a crack the surface runs
// on smoothly. Every other region is a crack or pinhole.
struct PinholeCount {
  int pinholes = 0, inside = 0;
};
// `full`: the alpha from which a pixel counts as covered.
PinholeCount count_pinholes(const RenderResult& r, float full_alpha = 1.0f - 1e-3f) {
  const int w = r.width, h = r.height;
  auto alpha = [&](int x, int y) { return r.rgba[(size_t(y) * w + x) * 4 + 3]; };
  auto depth = [&](int x, int y) { return r.depth[size_t(y) * w + x]; };
  auto full = [&](int x, int y) { return alpha(x, y) >= full_alpha; };
  std::vector<char> seen(size_t(w) * h, 0);
  PinholeCount c;
  for (int y0 = 0; y0 < h; ++y0)
    for (int x0 = 0; x0 < w; ++x0) {
      if (full(x0, y0)) {
        ++c.inside;
        continue;
      }
      if (seen[size_t(y0) * w + x0]) continue;
      std::vector<std::pair<int, int>> region;
      std::queue<std::pair<int, int>> q;
      q.push({x0, y0});
      seen[size_t(y0) * w + x0] = 1;
      bool edge = false;
      int uncovered = 0;
      float dmin = 3e38f, dmax = 0.0f;
      while (!q.empty()) {
        auto [x, y] = q.front();
        q.pop();
        region.push_back({x, y});
        edge |= x < 2 || y < 2 || x >= w - 2 || y >= h - 2;
        uncovered += alpha(x, y) < 1e-3f;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            if (full(xx, yy)) {
              dmin = std::min(dmin, depth(xx, yy)), dmax = std::max(dmax, depth(xx, yy));
            } else if (!seen[size_t(yy) * w + xx]) {
              seen[size_t(yy) * w + xx] = 1;
              q.push({xx, yy});
            }
          }
      }
      const bool past_silhouette = dmax > 1.1f * dmin;
      if (!(edge || uncovered >= 12 || past_silhouette)) c.pinholes += int(region.size());
    }
  return c;
}

class WatertightRender : public SharedRendererTest {};

TEST_F(WatertightRender, NoPinholesInsideTheSilhouetteFrom50Views) {
  std::mt19937 rng(4242);
  for (const Closed& object : closed_surfaces()) {
    int views_with_inside = 0;
    for (int view = 0; view < 50; ++view) {
      Scene s = view_scene(object, seeded_view(rng, object.radius), 160, 120);
      RenderResult r = renderer_->render(s);
      PinholeCount c = count_pinholes(r);
      views_with_inside += c.inside > 200;
      EXPECT_EQ(c.pinholes, 0) << object.name << ", view " << view << " of seed 4242: " << c.pinholes << " of "
                               << c.inside << " inside pixels have alpha below 1";
    }
    EXPECT_GE(views_with_inside, 40) << object.name;
  }
}

// Pixels farther than `reach` pixels (a square's half side) from any pixel
// less than half covered or past a silhouette (depth more than 10% off the
// pixel's: the torus' hole), and of those the ones with alpha below `full`.
// Near a blurred silhouette coverage is legitimately partial (and noisy: a
// pixel just inside the blur may miss one sample); farther in, a pixel that
// misses a sample sees through a crack.
PinholeCount count_deep_pinholes(const RenderResult& r, int reach, float full) {
  const int w = r.width, h = r.height;
  auto alpha = [&](int x, int y) { return r.rgba[(size_t(y) * w + x) * 4 + 3]; };
  auto depth = [&](int x, int y) { return r.depth[size_t(y) * w + x]; };
  PinholeCount c;
  for (int y = reach; y < h - reach; ++y)
    for (int x = reach; x < w - reach; ++x) {
      bool deep = true;
      const float d = depth(x, y);
      for (int dy = -reach; dy <= reach && deep; ++dy)
        for (int dx = -reach; dx <= reach && deep; ++dx)
          deep = alpha(x + dx, y + dy) >= 0.5f && std::fabs(depth(x + dx, y + dy) - d) <= 0.1f * d;
      if (!deep) continue;
      ++c.inside;
      c.pinholes += alpha(x, y) < full;
    }
  return c;
}

// Seen through a lens, every sample moves the grid's vertices alike, so a
// defocused closed surface has no pinholes either: away from its blurred
// silhouette, no pixel misses a sample (alpha below 1 - 0.5/spp with a box
// filter; the torus' hole counts as silhouette).
TEST_F(WatertightRender, NoPinholesOutOfFocus) {
  std::mt19937 rng(1723);
  for (const Closed& object : closed_surfaces()) {
    int views_with_inside = 0;
    for (int view = 0; view < 12; ++view) {
      Scene s = view_scene(object, seeded_view(rng, object.radius), 160, 120);
      s.settings.filter = PixelFilter::Box;
      s.settings.filter_width = 1.0f;
      const float distance = glm::length(glm::vec3(s.camera.world_to_camera[3]));
      // In front of or behind the object by turns, a few pixels of blur.
      s.camera.focus_distance = distance * (view % 2 ? 0.6f : 1.8f);
      s.camera.lens_radius = 0.1f * object.radius;
      s.camera.aperture_blades = view % 3 == 0 ? 6 : 0;
      RenderResult r = renderer_->render(s);
      const int spp = s.settings.samples_x * s.settings.samples_y;
      // The largest circle of confusion over the object's depths, in pixels.
      const FrameParams f = make_frame_setup(s).params;
      const float dmin = std::max(distance - object.radius, 0.05f * distance), dmax = distance + object.radius;
      const float coc = std::max(mp_coc_diameter(f, dmin), mp_coc_diameter(f, dmax));
      PinholeCount c = count_deep_pinholes(r, int(std::ceil(coc)) + 1, 1.0f - 0.5f / float(spp));
      views_with_inside += c.inside > 200;
      EXPECT_EQ(c.pinholes, 0) << object.name << ", defocused view " << view << " of seed 1723: " << c.pinholes
                               << " of " << c.inside << " inside pixels miss a sample";
    }
    EXPECT_GE(views_with_inside, 6) << object.name;
  }
}

// In motion, every sample sees the grid's vertices at its own time, and the
// steps are diced with the shutter centre's rates, so a moving closed
// surface has no pinholes either: away from its blurred silhouette (the
// farthest its points travel, plus a margin), no pixel misses a sample.
TEST_F(WatertightRender, NoPinholesInMotion) {
  std::mt19937 rng(917);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (const Closed& object : closed_surfaces()) {
    int views_with_inside = 0;
    for (int view = 0; view < 12; ++view) {
      Scene s = view_scene(object, seeded_view(rng, object.radius), 160, 120);
      s.settings.filter = PixelFilter::Box;
      s.settings.filter_width = 1.0f;
      s.motion_steps = 3;
      // A turn and a slide about the centre's place; the camera moves too in
      // every other view (the steps' camera transforms).
      const glm::vec3 slide = 0.03f * object.radius * glm::vec3(unit(rng), unit(rng), unit(rng));
      const glm::vec3 axis = glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)) + glm::vec3(0.0f, 0.0f, 1e-3f));
      for (int k = 0; k < 3; ++k) {
        const float t = float(k - 1);
        s.meshes[0].motion_object_to_world.push_back(glm::rotate(glm::translate(glm::mat4(1.0f), t * slide),
                                                                 t * 0.02f, axis));
        if (view % 2)
          s.camera.motion_world_to_camera.push_back(
              glm::translate(glm::mat4(1.0f), t * 0.01f * object.radius * glm::vec3(1.0f, 0.5f, 0.0f)) *
              s.camera.world_to_camera);
      }
      RenderResult r = renderer_->render(s);
      const int spp = s.settings.samples_x * s.settings.samples_y;
      // How far a point travels on screen: the slide and the turn at the
      // object's near side, and the camera's move, in pixels at its depth.
      const FrameParams f = make_frame_setup(s).params;
      const float distance = glm::length(glm::vec3(s.camera.world_to_camera[3]));
      const float near = std::max(distance - object.radius, 0.05f * distance);
      const float travel = glm::length(slide) + 0.02f * object.radius + (view % 2 ? 0.012f * object.radius : 0.0f);
      const int reach = int(std::ceil(std::fabs(f.ay) * travel / near)) + 2;
      PinholeCount c = count_deep_pinholes(r, reach, 1.0f - 0.5f / float(spp));
      views_with_inside += c.inside > 200;
      EXPECT_EQ(c.pinholes, 0) << object.name << ", moving view " << view << " of seed 917: " << c.pinholes << " of "
                               << c.inside << " inside pixels miss a sample";
    }
    EXPECT_GE(views_with_inside, 6) << object.name;
  }
}

// The check itself finds cracks: one face of a grid, given vertices of its
// own and shrunk by 2%, leaves a thin gap all round it.
TEST_F(WatertightRender, PinholeCountSeesAGap) {
  Scene s = base_scene(160, 120, 16);
  s.camera = look_at({0, 0, 4}, {0, 0, 0}, 40.0f);
  Mesh m = grid_mesh(4, 1.0f, SubdivScheme::None);
  const int face = 5, first = int(m.points.size());
  glm::vec3 centre(0.0f);
  for (int k = 0; k < 4; ++k) centre += 0.25f * m.points[size_t(m.face_vertex_indices[4 * face + k])];
  for (int k = 0; k < 4; ++k) {
    m.points.push_back(centre + 0.98f * (m.points[size_t(m.face_vertex_indices[4 * face + k])] - centre));
    m.face_vertex_indices[4 * face + k] = first + k;
  }
  s.meshes = {m};
  EXPECT_GT(count_pinholes(renderer_->render(s)).pinholes, 20);
  // And through a lens, with the threshold of NoPinholesOutOfFocus.
  s.settings.filter = PixelFilter::Box;
  s.settings.filter_width = 1.0f;
  s.camera.lens_radius = 0.05f;
  s.camera.focus_distance = 3.0f;
  const int spp = s.settings.samples_x * s.settings.samples_y;
  EXPECT_GT(count_deep_pinholes(renderer_->render(s), 3, 1.0f - 0.5f / float(spp)).pinholes, 20);
  // And in motion (a slide of about 2 pixels).
  s.camera.lens_radius = 0.0f;
  s.motion_steps = 2;
  s.meshes[0].motion_object_to_world = {glm::translate(glm::mat4(1.0f), glm::vec3(-0.02f, 0.01f, 0.0f)),
                                        glm::translate(glm::mat4(1.0f), glm::vec3(0.02f, -0.01f, 0.0f))};
  EXPECT_GT(count_deep_pinholes(renderer_->render(s), 4, 1.0f - 0.5f / float(spp)).pinholes, 20);
}

}  // namespace
}  // namespace mp::test
