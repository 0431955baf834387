// Shadows (kernels/shadow/mp_shadow.h): the host-side bookkeeping and map math,
// and renders measured against geometry: an orthographic camera looks
// straight down at a floor under an occluder it does not see (visible_camera
// false), so the floor shows the whole shadow, whose size, place and
// penumbra follow from similar triangles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_set>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "micropoly/settings_util.h"
#include "shadow/mp_shadow.h"
#include "pipeline/shadows/shadow_page_pool.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"
#include "scene/curves.h"

namespace mp::test {
namespace {

// ---- page pool ----------------------------------------------------------------

ShadowPageKey key(uint64_t light, int x, int y = 0, int map = 0) { return ShadowPageKey{light, map, x, y}; }

TEST(ShadowPagePool, KeepsResidentPagesAndRendersOnlyNewOnes) {
  ShadowPagePool pool(8);
  std::vector<ShadowPagePool::Grant> g;
  EXPECT_EQ(pool.grant({key(1, 0), key(1, 1), key(1, 2)}, g), 3u);
  for (const auto& x : g) EXPECT_TRUE(x.render);
  std::unordered_set<uint32_t> physical;
  for (const auto& x : g) physical.insert(x.physical);
  EXPECT_EQ(physical.size(), 3u);
  const uint32_t kept = g[1].physical;
  // The next frame asks for page 1 again and a new page 3: 1 keeps its page.
  EXPECT_EQ(pool.grant({key(1, 1), key(1, 3)}, g), 2u);
  EXPECT_FALSE(g[0].render);
  EXPECT_EQ(g[0].physical, kept);
  EXPECT_TRUE(g[1].render);
  EXPECT_EQ(pool.resident(), 4u);  // pages 0 and 2 stay cached until space is needed
}

TEST(ShadowPagePool, RendersAgainWhatWasRenderedForNearerReceivers) {
  // A page holds what lies in front of the receivers it was rendered for:
  // asked for with a farther receiver, it is rendered again, in its place;
  // asked for with a nearer one, or after being rendered uncapped, it is kept.
  ShadowPagePool pool(8);
  std::vector<ShadowPagePool::Grant> g;
  pool.grant({key(1, 0), key(1, 1)}, {10u, 10u}, g);
  const uint32_t first = g[0].physical;
  pool.grant({key(1, 0), key(1, 1)}, {20u, 5u}, g);
  EXPECT_TRUE(g[0].render);
  EXPECT_EQ(g[0].physical, first);
  EXPECT_FALSE(g[1].render);
  pool.grant({key(1, 0)}, {20u}, g);
  EXPECT_FALSE(g[0].render);
  pool.uncap(key(1, 1));
  pool.grant({key(1, 1)}, {1000u}, g);
  EXPECT_FALSE(g[0].render);
  pool.grant({key(1, 0)}, g);  // no caps: everything
  EXPECT_TRUE(g[0].render);
}

TEST(ShadowPagePool, EvictsLeastRecentlyUsedAndNeverExceedsCapacity) {
  ShadowPagePool pool(3);
  std::vector<ShadowPagePool::Grant> g;
  pool.grant({key(1, 0)}, g);
  pool.grant({key(1, 1)}, g);
  pool.grant({key(1, 2)}, g);
  const uint32_t oldest = g.empty() ? 0 : 0;
  (void)oldest;
  // A fourth page evicts page 0 (least recently used), not 2.
  ASSERT_EQ(pool.grant({key(1, 3)}, g), 1u);
  EXPECT_TRUE(g[0].render);
  EXPECT_EQ(pool.resident(), 3u);
  EXPECT_LE(pool.extent(), 3u);
  std::vector<ShadowPagePool::Grant> again;
  pool.grant({key(1, 2)}, again);
  EXPECT_FALSE(again[0].render) << "page 2 was evicted instead of page 0";
  // More requests than the capacity: the first ones get pages, the rest none.
  ASSERT_EQ(pool.grant({key(2, 0), key(2, 1), key(2, 2), key(2, 3), key(2, 4)}, g), 3u);
  EXPECT_NE(g[0].physical, ShadowPagePool::kNone);
  EXPECT_NE(g[2].physical, ShadowPagePool::kNone);
  EXPECT_EQ(g[3].physical, ShadowPagePool::kNone);
  EXPECT_EQ(g[4].physical, ShadowPagePool::kNone);
  EXPECT_LE(pool.resident(), 3u);
}

TEST(ShadowPagePool, ForgetsChangedLights) {
  ShadowPagePool pool(8);
  std::vector<ShadowPagePool::Grant> g;
  pool.grant({key(1, 0), key(2, 0), key(2, 1)}, g);
  pool.keep_only({2});
  EXPECT_EQ(pool.resident(), 2u);
  pool.grant({key(1, 0)}, g);
  EXPECT_TRUE(g[0].render) << "a changed light's page came back from the cache";
}

// ---- map math -----------------------------------------------------------------

TEST(ShadowMath, CubeFacesAreRotationsThatCoverEveryDirection) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int face = 0; face < 6; ++face) {
    glm::vec3 x = mp_cube_face_view(face, {1, 0, 0}), y = mp_cube_face_view(face, {0, 1, 0}),
              z = mp_cube_face_view(face, {0, 0, 1});
    EXPECT_NEAR(glm::determinant(glm::mat3(x, y, z)), 1.0f, 1e-6f) << "face " << face;
  }
  for (int i = 0; i < 1000; ++i) {
    glm::vec3 q(u(rng), u(rng), u(rng));
    int face = mp_cube_face(q);
    glm::vec3 v = mp_cube_face_view(face, q);
    EXPECT_GT(-v.z, 0.0f);  // in front of its face
    EXPECT_LE(std::abs(v.x), -v.z * 1.0001f);
    EXPECT_LE(std::abs(v.y), -v.z * 1.0001f);
    glm::vec3 back = mp_cube_face_unview(face, v);
    EXPECT_NEAR(glm::length(back - q), 0.0f, 1e-6f);
  }
}

TEST(ShadowMath, FaceBoxHoldsTheProjectionOfEveryPointOfTheBox) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f), s(0.01f, 2.0f), t(0.0f, 1.0f);
  const float texels = 1024.0f;
  int tested = 0;
  for (int i = 0; i < 300; ++i) {
    glm::vec3 c(u(rng), u(rng), u(rng)), h(s(rng), s(rng), s(rng));
    for (int face = 0; face < 6; ++face) {
      float x0, y0, x1, y1;
      int hit = mp_cube_face_box(face, c - h, c + h, texels, &x0, &y0, &x1, &y1);
      for (int k = 0; k < 50; ++k) {
        glm::vec3 p = c - h + 2.0f * h * glm::vec3(t(rng), t(rng), t(rng));
        if (mp_cube_face(p) != face) continue;
        glm::vec3 v = mp_cube_face_view(face, p);
        float rx = (v.x / -v.z + 1.0f) * 0.5f * texels, ry = (v.y / -v.z + 1.0f) * 0.5f * texels;
        ASSERT_TRUE(hit) << "a point of the box falls on face " << face << " but the box was not marked there";
        EXPECT_GE(rx, x0 - 1e-2f);
        EXPECT_LE(rx, x1 + 1e-2f);
        EXPECT_GE(ry, y0 - 1e-2f);
        EXPECT_LE(ry, y1 + 1e-2f);
        ++tested;
      }
    }
  }
  EXPECT_GT(tested, 5000);
}

// The receiver plane's depth at a texel is where that texel's ray meets it.
TEST(ShadowMath, ReceiverPlaneDepthIsTheRayPlaneIntersection) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  DeviceShadow sh{};
  sh.page_table = 0;
  sh.z_top = 5.0f;
  DeviceShadowLevel lv{};
  lv.offset[0] = 3.0f, lv.offset[1] = -2.0f, lv.texel = 0.01f;
  for (int i = 0; i < 500; ++i) {
    glm::vec3 q(u(rng), u(rng), -2.0f + u(rng));
    glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
    // A sun's level: rays run along -z.
    MpShadowMap sun = mp_sun_map(&sh, &lv);
    float x = 300.0f + 50.0f * u(rng), y = -200.0f + 50.0f * u(rng);
    if (std::abs(n.z) > 0.05f) {
      MpReceiverPlane p = mp_receiver_plane(&sun, q, n, 0.0f);
      glm::vec3 o(x / sun.scale - sun.off_x, y / sun.scale - sun.off_y, 0.0f);
      float z = q.z - (n.x * (o.x - q.x) + n.y * (o.y - q.y)) / n.z;
      EXPECT_NEAR(mp_plane_depth(&p, x, y, -1.0f), sh.z_top - z, 1e-3f);
    }
    // A cube face: rays from the light's position.
    int face = i % 6;
    MpShadowMap cube = mp_cube_map(&sh, face, 3);
    glm::vec3 qq = mp_cube_face_unview(face, glm::vec3(0.3f * u(rng), 0.3f * u(rng), -3.0f));
    MpReceiverPlane p = mp_receiver_plane(&cube, qq, n, 0.0f);
    float cx = cube.scale * (1.0f + 0.5f * u(rng)), cy = cube.scale * (1.0f + 0.5f * u(rng));
    glm::vec3 dir = mp_cube_face_unview(face, glm::vec3(cx / cube.scale - 1.0f, cy / cube.scale - 1.0f, -1.0f));
    float t = glm::dot(n, qq) / glm::dot(n, dir);
    if (t > 0.1f && t < 100.0f) EXPECT_NEAR(mp_plane_depth(&p, cx, cy, -1.0f), t, 1e-3f * t);
  }
}

TEST(ShadowMath, ExponentLog2AgreesWithTheLibrary) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> e(-30.0f, 30.0f);
  for (int i = 0; i < 10000; ++i) {
    float x = std::exp2(e(rng));
    EXPECT_EQ(mp_floor_log2(x), int(std::floor(std::log2(double(x))))) << x;
    EXPECT_EQ(mp_ceil_log2(x), int(std::ceil(std::log2(double(x))))) << x;
  }
  EXPECT_EQ(mp_floor_log2(1.0f), 0);
  EXPECT_EQ(mp_ceil_log2(1.0f), 0);
  EXPECT_EQ(mp_floor_log2(0.75f), -1);
  EXPECT_EQ(mp_ceil_log2(0.75f), 0);
}

// ---- renders ------------------------------------------------------------------

class ShadowRenderTest : public SharedRendererTest {};

constexpr int kW = 320, kH = 240;
constexpr float kHalfW = 4.0f, kHalfH = 3.0f;  // the camera's view of the floor, scene units

// A square area light of side w at height H over the floor, facing down.
Light square_area_light(float H, float w) {
  Light a;
  a.type = Light::Type::Area;
  a.intensity = 3.0f;
  a.position = glm::vec3(0, 0, H);
  a.direction = glm::vec3(0, 0, -1);
  a.axis_u = glm::vec3(1, 0, 0);
  a.size_u = a.size_v = w;
  return a;
}

// A white floor seen straight from above by an orthographic camera, lit by
// `light` alone; the occluders are added by the test.
Scene floor_scene(const Light& light) {
  Scene s;
  s.settings.width = kW;
  s.settings.height = kH;
  set_samples_per_pixel(s.settings, 16);
  s.settings.filter = PixelFilter::Box;
  s.settings.filter_width = 1.0f;
  s.settings.depth_and_normal_passes = false;
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.world_to_camera = glm::lookAt(glm::vec3(0, 0, 30), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0));
  s.camera.screen_left = -kHalfW, s.camera.screen_right = kHalfW;
  s.camera.screen_bottom = -kHalfH, s.camera.screen_top = kHalfH;
  s.camera.clip_near = 0.1f, s.camera.clip_far = 100.0f;
  Material m;
  m.model = Material::Model::Matte;
  m.color = glm::vec3(1.0f);
  m.kd = 1.0f;
  s.materials.push_back(m);
  s.lights.push_back(light);
  Mesh floor = polygon({{-20, -20, 0}, {20, -20, 0}, {20, 20, 0}, {-20, 20, 0}});
  floor.name = "floor";
  s.meshes.push_back(floor);
  return s;
}

// A horizontal rectangle [x0, x1] x [y0, y1] at height z that the camera
// does not see.
Mesh occluder(float x0, float y0, float x1, float y1, float z) {
  Mesh m = polygon({{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}});
  m.name = "occluder";
  m.visible_camera = false;
  return m;
}

glm::vec2 raster(glm::vec2 world) {
  return {(world.x + kHalfW) / (2 * kHalfW) * kW, (kHalfH - world.y) / (2 * kHalfH) * kH};
}

float luminance(const RenderResult& r, int x, int y) {
  const float* p = &r.rgba[4 * (size_t(y) * kW + x)];
  return (p[0] + p[1] + p[2]) / 3.0f;
}

// The fraction of the light each pixel gets: the render over the same
// render without shadows.
std::vector<float> visibility(Renderer& renderer, Scene s) {
  RenderResult lit_r, shadowed_r;
  s.settings.shadows = false;
  renderer.render(s, lit_r);
  s.settings.shadows = true;
  renderer.render(s, shadowed_r);
  std::vector<float> v(size_t(kW) * kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float lit = luminance(lit_r, x, y);
      v[size_t(y) * kW + x] = lit > 1e-6f ? luminance(shadowed_r, x, y) / lit : 1.0f;
    }
  return v;
}

struct ShadowShape {
  double area_px = 0;  // pixels below half the light
  glm::dvec2 centroid{0.0};
};

ShadowShape shadow_shape(const std::vector<float>& v) {
  ShadowShape s;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (v[size_t(y) * kW + x] < 0.5f) {
        s.area_px += 1;
        s.centroid += glm::dvec2(x + 0.5, y + 0.5);
      }
  if (s.area_px > 0) s.centroid /= s.area_px;
  return s;
}

constexpr double kPx = kW / (2.0 * kHalfW);  // pixels per scene unit

TEST_F(ShadowRenderTest, SunCastsTheOccludersShapeAlongItsDirection) {
  for (float slant : {0.0f, 0.6f}) {
    Light sun;
    sun.type = Light::Type::Distant;
    sun.intensity = 2.0f;
    sun.direction = glm::normalize(glm::vec3(slant, 0.0f, -1.0f));
    Scene s = floor_scene(sun);
    const float h = 1.5f;
    s.meshes.push_back(occluder(-1.0f, -0.5f, 0.6f, 0.7f, h));
    ShadowShape got = shadow_shape(visibility(*renderer_, s));
    // Straight down: the rectangle itself; slanted: moved by h * slant.
    const double area = 1.6 * 1.2 * kPx * kPx;
    glm::vec2 c = raster({-0.2f + h * slant, 0.1f});
    EXPECT_NEAR(got.area_px / area, 1.0, 0.02) << "slant " << slant;
    EXPECT_NEAR(got.centroid.x, c.x, 0.5) << "slant " << slant;
    EXPECT_NEAR(got.centroid.y, c.y, 0.5) << "slant " << slant;
  }
}

// A strand's shadow is a round tube's, whichever way the light comes from:
// a horizontal strand along y under a sun slanted by theta across it
// shadows a band 2 r / cos(theta) wide on the floor. Ribbons face the
// light's view, not the camera's (which looks straight down: a ribbon
// facing it would cast a band only 2 r wide): their shadow is the one of a
// flat plate square to the sun, to the pixel. The maps widen a band this
// thin by about half a pixel (3.6 % here, the plate's as well), and the
// tubes' 16 sides narrow it a little.
TEST_F(ShadowRenderTest, StrandsShadowAsRoundTubesFromASlantedSun) {
  const float theta = 0.9f, r = 0.12f, h = 1.0f;
  Light sun;
  sun.type = Light::Type::Distant;
  sun.intensity = 2.0f;
  sun.direction = glm::normalize(glm::vec3(std::sin(theta), 0.0f, -std::cos(theta)));
  const double area = 3.0 * 2.0 * r / std::cos(theta) * kPx * kPx;
  const glm::vec2 centre = raster({h * std::tan(theta), 0.0f});
  double got[3];  // tubes, ribbons, the plate
  for (int k = 0; k < 3; ++k) {
    Scene s = floor_scene(sun);
    if (k < 2) {
      CurveSet strand;
      strand.name = "strand";
      strand.points = {{0, -1.5f, h}, {0, 0, h}, {0, 1.5f, h}};
      strand.radii = {r, r, r};
      strand.offsets = {0, 3};
      strand.visible_camera = false;
      strand.ribbons = k == 1;
      ASSERT_EQ(add_curves(s, strand), 0u);
    } else {
      const glm::vec3 across = r * glm::vec3(std::cos(theta), 0.0f, std::sin(theta));
      Mesh plate = polygon({glm::vec3(0, -1.5f, h) - across, glm::vec3(0, -1.5f, h) + across,
                            glm::vec3(0, 1.5f, h) + across, glm::vec3(0, 1.5f, h) - across});
      plate.visible_camera = false;
      s.meshes.push_back(plate);
    }
    const ShadowShape shape = shadow_shape(visibility(*renderer_, s));
    got[k] = shape.area_px / area;
    EXPECT_NEAR(shape.centroid.x, centre.x, 0.5) << k;
    EXPECT_NEAR(got[k], 1.0, 0.045) << k;
  }
  EXPECT_NEAR(got[1] / got[2], 1.0, 0.005) << "ribbons " << got[1] << ", plate " << got[2];
}

TEST_F(ShadowRenderTest, PointAndSpotLightsMagnifyTheShadowBySimilarTriangles) {
  for (Light::Type type : {Light::Type::Point, Light::Type::Spot}) {
    Light l;
    l.type = type;
    l.intensity = 40.0f;
    l.position = glm::vec3(0.3f, -0.2f, 4.0f);
    l.direction = glm::vec3(0, 0, -1);
    l.cone_angle = 1.2f;
    l.cone_delta_angle = 0.1f;
    l.beam_distribution = 0.0f;
    Scene s = floor_scene(l);
    const float h = 1.6f, k = 4.0f / (4.0f - h);  // shadow / occluder size
    s.meshes.push_back(occluder(-0.6f, -0.4f, 0.4f, 0.5f, h));
    ShadowShape got = shadow_shape(visibility(*renderer_, s));
    const double area = 1.0 * 0.9 * k * k * kPx * kPx;
    // The shadow's centre: the occluder's centre pushed away from the light.
    glm::vec2 oc(-0.1f, 0.05f), lp(0.3f, -0.2f);
    glm::vec2 c = raster(lp + (oc - lp) * k);
    EXPECT_NEAR(got.area_px / area, 1.0, 0.02) << (type == Light::Type::Point ? "point" : "spot");
    EXPECT_NEAR(got.centroid.x, c.x, 0.5);
    EXPECT_NEAR(got.centroid.y, c.y, 0.5);
  }
}

// Across the edge of an occluder that covers x < 0, the light a floor point
// sees grows over a penumbra; the distances between its 10% and 90% points
// are the references (similar triangles and the light's shape).
double ramp_width(const std::vector<float>& v, int row) {
  auto crossing = [&](float level) {
    for (int x = 1; x < kW; ++x) {
      float a = v[size_t(row) * kW + x - 1], b = v[size_t(row) * kW + x];
      if (a < level && b >= level) return x - 0.5 + (level - a) / (b - a);
    }
    return -1.0;
  };
  double lo = crossing(0.1f), hi = crossing(0.9f);
  return lo < 0 || hi < 0 ? -1.0 : hi - lo;
}

// 10%-90% width of the fraction of a unit-diameter disk on one side of a
// line as the line sweeps across it.
double disk_ramp_width() {
  auto fraction = [](double t) {  // t in [-0.5, 0.5]: the line's offset from the centre
    const double r = 0.5, d = std::clamp(t, -r, r);
    return (r * r * std::acos(-d / r) + d * std::sqrt(r * r - d * d)) / (3.14159265358979 * r * r);
  };
  auto solve = [&](double f) {
    double a = -0.5, b = 0.5;
    for (int i = 0; i < 60; ++i) (fraction(0.5 * (a + b)) < f ? a : b) = 0.5 * (a + b);
    return 0.5 * (a + b);
  };
  return solve(0.9) - solve(0.1);
}

TEST_F(ShadowRenderTest, PenumbraWidensWithTheLightsSizeAsSimilarTrianglesSay) {
  const float h = 1.0f, H = 5.0f;
  struct Case {
    const char* what;
    Light light;
    double expected_px;
  };
  std::vector<Case> cases;
  {
    Light a = square_area_light(H, 2.0f);  // a linear ramp over w h / (H - h)
    cases.push_back({"area light", a, 0.8 * 2.0 * h / (H - h) * kPx});
  }
  {
    Light p;  // a point light of radius r: a disk of diameter 2r
    p.type = Light::Type::Point;
    p.intensity = 30.0f;
    p.position = glm::vec3(0, 0, H);
    p.radius = 1.0f;
    cases.push_back({"point light with radius", p, disk_ramp_width() * 2.0 * h / (H - h) * kPx});
  }
  {
    Light sun;  // a sun of angular diameter a: a disk of diameter 2 h tan(a / 2)
    sun.type = Light::Type::Distant;
    sun.direction = glm::vec3(0, 0, -1);
    sun.angle = 0.5f;
    cases.push_back({"sun with an angle", sun, disk_ramp_width() * 2.0 * h * std::tan(0.25) * kPx});
  }
  for (const Case& c : cases) {
    Scene s = floor_scene(c.light);
    s.meshes.push_back(occluder(-20.0f, -20.0f, 0.0f, 20.0f, h));
    std::vector<float> v = visibility(*renderer_, s);
    double w = ramp_width(v, kH / 2);
    if (getenv("MP_PRINT_RAMP")) {
      for (int x = kW / 2 - 20; x < kW / 2 + 20; ++x) printf("%.2f ", v[size_t(kH / 2) * kW + x]);
      printf("\n");
    }
    ASSERT_GT(w, 0.0) << c.what << ": no penumbra crossing on the middle row";
    EXPECT_NEAR(w / c.expected_px, 1.0, 0.15) << c.what << ": " << w << " px against " << c.expected_px;
    // No light in the umbra far under the occluder, all of it far outside.
    EXPECT_LT(v[size_t(kH / 2) * kW + 10], 0.02f) << c.what;
    EXPECT_GT(v[size_t(kH / 2) * kW + kW - 10], 0.98f) << c.what;
  }
}

TEST_F(ShadowRenderTest, ContactShadowsStartAtTheContact) {
  // A box standing on the floor under a slanted sun: the floor right at the
  // box's foot on the far side is in shadow (no gap of light).
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(1.0f, 0.0f, -1.0f));
  Scene s = floor_scene(sun);
  Mesh box = cube_mesh(SubdivScheme::None);
  box.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 0.5f)) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
  box.visible_camera = false;
  s.meshes.push_back(box);
  std::vector<float> v = visibility(*renderer_, s);
  // The shadow covers x in [0.5, 1.5] (height 1 at 45 degrees) on y = 0.
  const int row = kH / 2;
  for (float x : {0.52f, 0.8f, 1.2f, 1.45f})
    EXPECT_LT(v[size_t(row) * kW + int(raster({x, 0}).x)], 0.05f) << "light at x = " << x;
  for (float x : {1.6f, 2.5f}) EXPECT_GT(v[size_t(row) * kW + int(raster({x, 0}).x)], 0.95f) << "shadow at x = " << x;
}

TEST_F(ShadowRenderTest, ControlsTurnShadowsOffWhereAsked) {
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::vec3(0, 0, -1);
  Scene s = floor_scene(sun);
  s.meshes.push_back(occluder(-1.0f, -1.0f, 1.0f, 1.0f, 1.0f));
  auto centre = [&](const Scene& scene) { return visibility(*renderer_, scene)[size_t(kH / 2) * kW + kW / 2]; };
  EXPECT_LT(centre(s), 0.02f);
  Scene no_light_shadow = s;
  no_light_shadow.lights[0].cast_shadows = false;
  EXPECT_GT(centre(no_light_shadow), 0.98f);
  Scene no_caster = s;
  no_caster.meshes[1].cast_shadows = false;
  EXPECT_GT(centre(no_caster), 0.98f);
  // Half opacity lets half the light through (stochastic per texel: the
  // average over the shadow).
  Scene half = s;
  Material glass = half.materials[0];
  glass.opacity = glm::vec3(0.5f);
  half.materials.push_back(glass);
  half.meshes[1].material = 1;
  std::vector<float> v = visibility(*renderer_, half);
  double sum = 0;
  int n = 0;
  for (int y = kH / 2 - 15; y < kH / 2 + 15; ++y)
    for (int x = kW / 2 - 15; x < kW / 2 + 15; ++x) sum += v[size_t(y) * kW + x], ++n;
  EXPECT_NEAR(sum / n, 0.5, 0.05);
}

TEST_F(ShadowRenderTest, DisplacementMovesTheShadow) {
  // A program that lifts the occluder by 1 unit: its shadow under a
  // slanted sun moves by the sun's slant.
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(0.5f, 0.0f, -1.0f));
  Scene s = floor_scene(sun);
  s.material_programs.push_back(
      {"lift", "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f, 0.0f, 1.0f); }\n"
               "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n"});
  Material lifted = s.materials[0];
  lifted.program = 0;
  lifted.program_displaces = true;
  lifted.displacement_bound = 1.0f;
  s.materials.push_back(lifted);
  Mesh o = occluder(-0.5f, -0.5f, 0.5f, 0.5f, 1.0f);
  o.material = 1;
  s.meshes.push_back(o);
  ShadowShape got = shadow_shape(visibility(*renderer_, s));
  // At height 2 the shadow's centre is at x = 2 * 0.5 = 1 (at height 1, 0.5).
  EXPECT_NEAR(got.centroid.x, raster({1.0f, 0.0f}).x, 0.6);
  EXPECT_NEAR(got.area_px / (kPx * kPx), 1.0, 0.03);
}

// A slanted sun over the floor and a square occluder, for the tests of
// pages kept from frame to frame.
Scene slanted_sun_over_occluder() {
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(0.3f, 0.2f, -1.0f));
  Scene s = floor_scene(sun);
  s.meshes.push_back(occluder(-1.0f, -1.0f, 1.0f, 1.0f, 1.0f));
  return s;
}

TEST_F(ShadowRenderTest, PagesAreKeptBetweenFramesWhileLightsAndGeometryStay) {
  Scene s = slanted_sun_over_occluder();
  Renderer fresh;
  RenderResult first = renderer_->render(s), again = renderer_->render(s);
  ASSERT_GT(first.stats.shadows.pages_rendered, 0u);
  EXPECT_EQ(again.stats.shadows.pages_rendered, 0u) << "an unchanged frame rendered its shadow pages again";
  EXPECT_EQ(again.stats.shadows.pages_requested, first.stats.shadows.pages_requested);
  EXPECT_EQ(first.rgba, again.rgba);
  // The light turns: every page of it is new, and the image is what a
  // renderer that never saw the first light makes.
  s.lights[0].direction = glm::normalize(glm::vec3(-0.3f, 0.2f, -1.0f));
  RenderResult turned = renderer_->render(s);
  EXPECT_EQ(turned.stats.shadows.pages_rendered, turned.stats.shadows.pages_requested);
  EXPECT_EQ(turned.rgba, fresh.render(s).rgba);
}

TEST_F(ShadowRenderTest, PagesAreKeptWhileOnlyShadingChanges) {
  // The occluder's node tree changes from one frame to the next. While it
  // only shades (an artist grading a material and pressing F12 again), the
  // pages are kept: none is rendered, the image is what a renderer that
  // never saw the first tree makes, and a new name changes nothing either.
  // Once the tree displaces, every page is new.
  Scene s = slanted_sun_over_occluder();
  s.meshes.back().visible_camera = true;  // its colour shows
  const std::string flat = "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }\n";
  auto shading = [&](const char* name, const char* colour) {
    s.material_programs = {{name, flat + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                         " mp_add_emission(s, (float3)(" + colour + ")); }\n"}};
    s.materials.resize(1);
    s.materials.push_back(s.materials[0]);
    s.materials[1].program = 0;
    s.materials[1].program_shades = true;
    s.meshes.back().material = 1;
  };
  shading("red", "0.5f, 0.0f, 0.0f");
  const RenderResult red = renderer_->render(s);
  ASSERT_GT(red.stats.shadows.pages_rendered, 0u);
  shading("green", "0.0f, 0.5f, 0.0f");
  s.meshes.back().name = "renamed";
  const RenderResult green = renderer_->render(s);
  EXPECT_EQ(green.stats.shadows.pages_rendered, 0u) << "a tree that only shades rendered the shadow pages again";
  EXPECT_EQ(green.stats.shadows.pages_requested, red.stats.shadows.pages_requested);
  EXPECT_NE(green.rgba, red.rgba);
  EXPECT_EQ(green.rgba, Renderer().render(s).rgba);
  // The same tree now lifts the occluder: its shadow moves, and the pages
  // it reaches are rendered again.
  s.material_programs[0].source =
      "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f, 0.0f, 0.5f); }\n"
      "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n";
  s.materials[1].program_displaces = true;
  s.materials[1].displacement_bound = 0.5f;
  const RenderResult lifted = renderer_->render(s);
  EXPECT_GT(lifted.stats.shadows.pages_rendered, 0u);
  EXPECT_EQ(lifted.rgba, Renderer().render(s).rgba);
}

TEST_F(ShadowRenderTest, ACancelledFrameLeavesNoUnrenderedPageBehind) {
  // Cancelled at each of its first progress calls (some fall while the
  // pages are rendered), the renderer then renders the frame as a renderer
  // that never saw the cancelled one.
  Scene s = slanted_sun_over_occluder();
  int asked = 0;
  const RenderResult fresh = Renderer().render(s, [&](float) { return ++asked > 0; });
  bool cancelled_in_shadows = false;
  for (int at = 2; at <= std::min(asked, 12); ++at) {
    Renderer r;
    int calls = 0;
    const RenderResult cancelled = r.render(s, [&](float) { return ++calls < at; });
    ASSERT_TRUE(cancelled.stats.cancelled) << at;
    cancelled_in_shadows = cancelled_in_shadows || cancelled.stats.shadows.pages_rendered > 0;
    EXPECT_EQ(r.render(s).rgba, fresh.rgba) << "cancelled at progress call " << at;
  }
  EXPECT_TRUE(cancelled_in_shadows) << "no cancel fell after pages were granted (" << asked << " progress calls)";
}

TEST_F(ShadowRenderTest, PagesOutsideAChangedSurfaceAreKept) {
  // A soft sun and a point lamp with a radius (a clipmap and a cube) over
  // two occluders far apart. One moves, then another is added and the
  // first removed, as in a viewport's edits: each time only the pages the
  // changed surface reaches, where it was or where it is, are rendered
  // again, and the image is what a renderer that never saw the frames
  // before makes.
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(0.3f, 0.2f, -1.0f));
  sun.angle = 0.05f;
  Scene s = floor_scene(sun);
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.intensity = 40.0f;
  lamp.position = glm::vec3(0.5f, -0.5f, 5.0f);
  lamp.radius = 0.2f;
  s.lights.push_back(lamp);
  s.meshes.push_back(occluder(-3.5f, -2.5f, -2.5f, -1.5f, 1.0f));
  s.meshes.push_back(occluder(2.0f, 1.0f, 3.0f, 2.0f, 1.0f));
  const RenderResult first = renderer_->render(s);
  ASSERT_GT(first.stats.shadows.pages_rendered, 0u);
  auto expect_partly_kept = [&](const char* what) {
    const RenderResult now = renderer_->render(s);
    EXPECT_GT(now.stats.shadows.pages_rendered, 0u) << what;
    EXPECT_LT(now.stats.shadows.pages_rendered, now.stats.shadows.pages_requested) << what;
    EXPECT_EQ(now.rgba, Renderer().render(s).rgba) << what;
  };
  s.meshes[2].object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, -0.2f, 0.0f));
  expect_partly_kept("the second occluder moved");
  s.meshes.push_back(occluder(-3.0f, 1.5f, -2.6f, 1.9f, 0.5f));
  expect_partly_kept("an occluder added");
  s.meshes.erase(s.meshes.begin() + 1);
  expect_partly_kept("the first occluder removed");
  // The same surfaces in another order change nothing.
  std::swap(s.meshes[1], s.meshes[2]);
  EXPECT_EQ(renderer_->render(s).stats.shadows.pages_rendered, 0u);
}

TEST_F(ShadowRenderTest, KeptPagesAreRenderedAgainWhereTheirReceiversNowLieFarther) {
  // The first frame sees only a tile high above the floor, so its pages
  // hold only what lies in front of the tile, and an occluder below it is
  // left out. The camera then pans (the same pixel size, so the same
  // levels) to the floor beside the tile, where that occluder's shadow falls
  // in some of the same pages: those are rendered again, and the frame is
  // what a renderer that never saw the first makes.
  Light sun;
  sun.type = Light::Type::Distant;
  sun.direction = glm::normalize(glm::vec3(0.3f, 0.0f, -1.0f));
  Scene s = floor_scene(sun);
  s.meshes.push_back(polygon({{-0.6f, -0.6f, 2.0f}, {0.6f, -0.6f, 2.0f}, {0.6f, 0.6f, 2.0f}, {-0.6f, 0.6f, 2.0f}}));
  s.meshes.push_back(occluder(0.9f, -0.2f, 1.2f, 0.2f, 1.0f));
  auto window = [&](float x0) {
    s.camera.screen_left = x0, s.camera.screen_right = x0 + 0.8f;
    s.camera.screen_bottom = -0.3f, s.camera.screen_top = 0.3f;
  };
  window(-0.2f);  // the tile's top up to its right edge, and nothing else
  const RenderResult tile = renderer_->render(s);
  ASSERT_GT(tile.stats.shadows.pages_rendered, 0u);
  window(0.8f);
  const RenderResult panned = renderer_->render(s);
  EXPECT_GT(panned.stats.shadows.pages_rendered, 0u);
  EXPECT_EQ(panned.rgba, Renderer().render(s).rgba);
}

TEST_F(ShadowRenderTest, BoundSplitStrategiesMakeTheSameShadows) {
  Light spot;
  spot.type = Light::Type::Spot;
  spot.intensity = 50.0f;
  spot.position = glm::vec3(1, -1, 4);
  spot.direction = glm::normalize(glm::vec3(-1, 1, -4));
  spot.cone_angle = 0.8f;
  spot.radius = 0.3f;
  Scene s = floor_scene(spot);
  Mesh torus = torus_mesh(12, 8, 0.3f, SubdivScheme::CatmullClark);
  torus.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 1));
  s.meshes.push_back(torus);
  s.settings.bound_split = BoundSplitMethod::Bounded;
  RenderResult bounded = Renderer().render(s);
  s.settings.bound_split = BoundSplitMethod::Breadth;
  RenderResult breadth = Renderer().render(s);
  ASSERT_GT(bounded.stats.shadows.pages_rendered, 0u);
  EXPECT_EQ(bounded.rgba, breadth.rgba);
}

TEST_F(ShadowRenderTest, PreviewPenumbraeWithoutTheirFinerPagesKeepTheirWidth) {
  // The viewport's preview skips soft shadows' second marking: no more pages
  // (here, where the first marking's levels already hold the penumbra, no
  // fewer either), and a penumbra still about as wide as similar triangles
  // say.
  const float h = 1.0f, H = 5.0f;
  Scene s = floor_scene(square_area_light(H, 2.0f));
  s.meshes.push_back(occluder(-20.0f, -20.0f, 0.0f, 20.0f, h));
  const RenderResult full = Renderer().render(s);
  s.settings.soft_shadow_pages = false;
  const RenderResult preview = Renderer().render(s);
  EXPECT_LE(preview.stats.shadows.pages_requested, full.stats.shadows.pages_requested);
  EXPECT_EQ(preview.stats.shadows.pages_missing, 0u);
  std::vector<float> v = visibility(*renderer_, s);
  const double w = ramp_width(v, kH / 2), expected = 0.8 * 2.0 * h / (H - h) * kPx;
  ASSERT_GT(w, 0.0);
  EXPECT_NEAR(w / expected, 1.0, 0.25) << w << " px against " << expected;
  EXPECT_LT(v[size_t(kH / 2) * kW + 10], 0.02f);
  EXPECT_GT(v[size_t(kH / 2) * kW + kW - 10], 0.98f);
}

TEST_F(ShadowRenderTest, AShortBudgetCoarsensShadowsAndKeepsToIt) {
  Light point;
  point.type = Light::Type::Point;
  point.intensity = 40.0f;
  point.position = glm::vec3(0.5f, 0.5f, 3.0f);
  Scene s = floor_scene(point);
  s.meshes.push_back(occluder(-1.0f, -1.0f, 1.0f, 1.0f, 1.0f));
  RenderResult full = renderer_->render(s);
  ASSERT_EQ(full.stats.shadows.level_bias, 0);
  s.settings.shadow_memory_mib = 2.5f;
  RenderResult short_budget = Renderer().render(s);
  const ShadowStats& st = short_budget.stats.shadows;
  EXPECT_GT(st.level_bias + int(st.pages_missing), 0) << "the budget was not short";
  EXPECT_LE(st.peak_bytes, st.budget_bytes);
  // Still a shadow where the occluder is.
  EXPECT_LT(luminance(short_budget, kW / 2, kH / 2), 0.2f * luminance(short_budget, 5, 5));
  s.settings.shadow_memory_mib = 0.25f;
  try {
    Renderer().render(s);
    FAIL() << "a budget too small for the page tables rendered";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shadow map memory budget"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mp::test

namespace mp::test {
namespace {

// A stack of `layers` horizontal squares 4 units across, 0.05 apart from
// height 1 up, that the camera sees (only the top one, from above), lit by
// a point light of radius 0.2 above them: each layer hides the ones below
// from the light.
Scene layer_stack(int layers) {
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.intensity = 60.0f;
  lamp.position = glm::vec3(1.0f, 0.5f, 6.0f);
  lamp.radius = 0.2f;
  Scene s = floor_scene(lamp);
  for (int k = 0; k < layers; ++k) {
    const float z = 1.0f + 0.05f * float(k);
    Mesh m = polygon({{-2, -2, z}, {2, -2, z}, {2, 2, z}, {-2, 2, z}});
    m.name = "layer" + std::to_string(k);
    s.meshes.push_back(m);
  }
  return s;
}

TEST_F(ShadowRenderTest, HiddenLayersAreCulledFromTheLightsViewsWithoutChangingTheImage) {
  Scene s = layer_stack(48);
  s.settings.occlusion_culling = false;
  const RenderResult all = Renderer().render(s);  // fresh renderers: no pages kept from the frame before
  s.settings.occlusion_culling = true;
  const RenderResult culled = Renderer().render(s);
  const RenderResult one = Renderer().render(layer_stack(1));
  const ShadowStats &a = all.stats.shadows, &c = culled.stats.shadows;
  ASSERT_GT(a.pages_rendered, 0u);
  EXPECT_EQ(a.subpatches_occluded, 0u);
  // Texels keep the nearest depth they see, so what culling leaves out could
  // not have changed one; the pages left out were asked for by hidden
  // receivers only, which no pixel reads.
  EXPECT_EQ(culled.rgba, all.rgba);
  EXPECT_LE(c.pages_rendered, a.pages_rendered);
  EXPECT_LE(c.micropolygons, a.micropolygons);
  // A GPU takes every root at once and looks at its pyramids between dice
  // batches only (as in the camera's view): this small scene is one batch.
  if (Renderer().device().type != "cpu") GTEST_SKIP() << "waves near to far are for CPU devices";
  EXPECT_GT(c.subpatches_occluded, 0u);
  // The lights' views dice little more than the top layer.
  EXPECT_LT(double(c.micropolygons), 0.25 * double(a.micropolygons)) << c.micropolygons << " of " << a.micropolygons;
  EXPECT_LT(double(c.micropolygons), 1.5 * double(one.stats.shadows.micropolygons))
      << c.micropolygons << " shadow micropolygons for 48 layers, " << one.stats.shadows.micropolygons << " for one";
}

TEST_F(ShadowRenderTest, OnlyWhatTheCameraSeesAsksForPages) {
  // Seen from above, 48 stacked layers under a wider top one show only the
  // top and the floor around: with culling, the marking's coarse depth
  // leaves the hidden layers' receivers out, so the pages asked for are
  // those asked for when the camera cannot see those layers at all (they
  // cast the same shadows either way); without culling, every layer asks
  // for its own.
  Scene s = layer_stack(48);
  const float z = s.meshes.back().points[0].z;
  s.meshes.back() = polygon({{-2.5f, -2.5f, z}, {2.5f, -2.5f, z}, {2.5f, 2.5f, z}, {-2.5f, 2.5f, z}});
  Scene unseen = s;
  for (size_t m = 1; m + 1 < unseen.meshes.size(); ++m) unseen.meshes[m].visible_camera = false;
  const RenderResult reference = Renderer().render(unseen);
  const RenderResult culled = Renderer().render(s);
  s.settings.occlusion_culling = false;
  const RenderResult all = Renderer().render(s);
  const ShadowStats &r = reference.stats.shadows, &c = culled.stats.shadows, &a = all.stats.shadows;
  ASSERT_GT(r.pages_requested, 0u);
  EXPECT_EQ(c.pages_requested, r.pages_requested);
  EXPECT_GT(a.pages_requested, c.pages_requested);
  EXPECT_EQ(a.marking_occluded, 0u);
  EXPECT_EQ(culled.rgba, reference.rgba);
  EXPECT_EQ(culled.rgba, all.rgba);
}

TEST_F(ShadowRenderTest, NothingBeyondTheFarthestReceiverIsRendered) {
  // The camera sees a tile that fills its frame; beside it, outside the
  // frame and below the tile (farther from the lamp above than any
  // receiver), lie 48 layers that the lamp sees in the same pages as the
  // tile. They can shadow no receiver, so the lights' views leave them out:
  // the same image and about the shadow micropolygons of the tile alone.
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.intensity = 60.0f;
  lamp.position = glm::vec3(0.0f, 0.0f, 6.0f);
  lamp.radius = 0.2f;
  Scene tile = floor_scene(lamp);
  tile.meshes.front() = polygon({{-4.5f, -3.5f, 1.0f}, {4.5f, -3.5f, 1.0f}, {4.5f, 3.5f, 1.0f}, {-4.5f, 3.5f, 1.0f}});
  Scene s = tile;
  for (int k = 0; k < 48; ++k) {
    const float z = -0.05f * float(k);
    s.meshes.push_back(polygon({{4.6f, -3.0f, z}, {9.0f, -3.0f, z}, {9.0f, 3.0f, z}, {4.6f, 3.0f, z}}));
  }
  const RenderResult alone = Renderer().render(tile);
  const RenderResult beside = Renderer().render(s);
  s.settings.occlusion_culling = false;
  const RenderResult all = Renderer().render(s);
  const size_t a = alone.stats.shadows.micropolygons, b = beside.stats.shadows.micropolygons;
  ASSERT_GT(a, 0u);
  EXPECT_EQ(beside.rgba, alone.rgba);
  EXPECT_EQ(all.rgba, alone.rgba);
  EXPECT_EQ(beside.stats.shadows.pages_requested, alone.stats.shadows.pages_requested);
  EXPECT_LT(double(b), 1.1 * double(a)) << b << " shadow micropolygons with the layers beside, " << a << " without";
  EXPECT_GT(double(all.stats.shadows.micropolygons), 2.0 * double(a)) << "the layers lie outside the tile's pages";
}

TEST_F(ShadowRenderTest, MarkingVerticesKeepToTheirShareOfTheBudget) {
  // Enough layers that the soft marking's vertices pass an eighth of a
  // 7 MiB budget: the marking dices the view again rather than keep them,
  // and the pages (and so the image) are those of an ample budget.
  Scene s = layer_stack(160);
  s.settings.occlusion_culling = false;
  const RenderResult ample = Renderer().render(s);
  s.settings.shadow_memory_mib = 7.0f;
  const RenderResult tight = Renderer().render(s);
  const ShadowStats& t = tight.stats.shadows;
  EXPECT_EQ(ample.stats.shadows.marking_passes, 0u);
  EXPECT_GE(t.marking_passes, 1u) << "the kept vertices fitted: the test needs more of them";
  EXPECT_LE(t.peak_bytes, t.budget_bytes);
  ASSERT_EQ(t.level_bias, 0);
  ASSERT_EQ(t.pages_missing, 0u);
  EXPECT_EQ(t.pages_requested, ample.stats.shadows.pages_requested);
  EXPECT_EQ(tight.rgba, ample.rgba);
}

}  // namespace
}  // namespace mp::test
