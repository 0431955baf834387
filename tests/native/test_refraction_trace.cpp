// Paths through refracting objects (kernels/geometry/mp_refract_trace.h) against
// Snell's law worked out by hand for a sphere and a box, and the proxy
// builder (native/src/pipeline/materials/refraction_proxy.cpp) against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "geometry/mp_refract_trace.h"
#include "pipeline/materials/refraction_proxy.h"
#include "scene_fixtures.h"
#include "renderer_fixture.h"
#include "subdiv/patch_buffer.h"

#include <glm/gtc/matrix_transform.hpp>

namespace {

constexpr float kPi = 3.14159265358979f;

// A unit sphere at `centre`: rings x segments quads as triangles, with the
// sphere's exact normals at their corners.
std::vector<mp::ProxyTriangle> sphere(glm::vec3 centre, int rings, int segments) {
  auto at = [&](int r, int k) {
    const float th = kPi * float(r) / float(rings), ph = 2.0f * kPi * float(k) / float(segments);
    return glm::vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  };
  std::vector<mp::ProxyTriangle> out;
  auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    if (glm::dot(glm::cross(b - a, c - a), a + b + c) < 0.0f) std::swap(b, c);
    if (!(glm::length(glm::cross(b - a, c - a)) > 0.0f)) return;
    out.push_back({{centre + a, centre + b, centre + c}, {a, b, c}});
  };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      tri(at(r, k), at(r + 1, k), at(r + 1, k + 1));
      tri(at(r, k), at(r + 1, k + 1), at(r, k + 1));
    }
  return out;
}

// An axis-aligned box with flat faces.
std::vector<mp::ProxyTriangle> box(glm::vec3 lo, glm::vec3 hi) {
  std::vector<mp::ProxyTriangle> out;
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      glm::vec3 n(0.0f);
      n[axis] = side ? 1.0f : -1.0f;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      glm::vec3 q[4];
      for (int c = 0; c < 4; ++c) {
        q[c][axis] = side ? hi[axis] : lo[axis];
        q[c][u] = (c == 1 || c == 2) ? hi[u] : lo[u];
        q[c][v] = (c >= 2) ? hi[v] : lo[v];
      }
      for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        mp::ProxyTriangle p{{q[t[0]], q[t[1]], q[t[2]]}, {n, n, n}};
        if (glm::dot(glm::cross(p.p[1] - p.p[0], p.p[2] - p.p[0]), p.p[0] - centre) < 0.0f) std::swap(p.p[1], p.p[2]);
        out.push_back(p);
      }
    }
  return out;
}

struct Proxy {
  mp::RefractionProxies data;
  MpRefractScene scene;
  explicit Proxy(std::vector<mp::ProxyTriangle> tris) {
    const uint32_t root = mp::append_refraction_proxy(tris, data);
    scene = MpRefractScene{data.nodes.data(), data.tris.data(), root};
  }
};

glm::vec3 refract(glm::vec3 d, glm::vec3 n, float eta) {  // n faces against d
  const float c = -glm::dot(d, n), k = 1.0f - eta * eta * (1.0f - c * c);
  return glm::normalize(eta * d + (eta * c - std::sqrt(k)) * n);
}

float angle_deg(glm::vec3 a, glm::vec3 b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)) * 180.0f / kPi;
}

}  // namespace

// A ray entering a sphere at impact parameter b leaves it turned towards
// the axis by 2 (theta_i - theta_t), after one more surface (Refraction:
// all of it, times the tint once more).
TEST(RefractionTrace, SphereExitFollowsSnellsLaw) {
  Proxy proxy(sphere(glm::vec3(0.0f), 256, 512));
  const float ior = 1.45f;
  for (float b : {0.1f, 0.4f, 0.7f, 0.9f}) {
    SCOPED_TRACE(b);
    const glm::vec3 p(b, 0.0f, -std::sqrt(1.0f - b * b)), d0(0.0f, 0.0f, 1.0f);
    const glm::vec3 t = refract(d0, p, 1.0f / ior);
    MpRefractExits ex;
    const glm::vec3 tint(0.9f, 0.8f, 0.7f);
    mp_refract_paths(&proxy.scene, p, t, 1e-4f, 1e-5f, ior, 0, tint, &ex);
    ASSERT_EQ(ex.count, 1);
    const float ti = std::asin(b), tt = std::asin(b / ior), dev = 2.0f * (ti - tt);
    const glm::vec3 expected(-std::sin(dev), 0.0f, std::cos(dev));
    EXPECT_LT(angle_deg(ex.dir[0], expected), 0.2f);
    EXPECT_NEAR(ex.weight[0].x, tint.x, 1e-5f);
    EXPECT_NEAR(ex.weight[0].z, tint.z, 1e-5f);
    EXPECT_EQ(ex.interfaces[0], 2);
  }
}

// Glass splits every hit by the Fresnel term: inside a sphere every hit
// meets the surface at theta_t, so the paths leave with (1 - F) F^k, and
// together they carry all that entered but what was dropped for being small.
TEST(RefractionTrace, SphereGlassConservesWhatEnters) {
  Proxy proxy(sphere(glm::vec3(0.0f), 256, 512));
  const float ior = 1.5f;
  for (float b : {0.3f, 0.95f}) {
    SCOPED_TRACE(b);
    const glm::vec3 p(b, 0.0f, -std::sqrt(1.0f - b * b));
    const glm::vec3 t = refract(glm::vec3(0.0f, 0.0f, 1.0f), p, 1.0f / ior);
    MpRefractExits ex;
    mp_refract_paths(&proxy.scene, p, t, 1e-4f, 1e-5f, ior, 1, glm::vec3(1.0f), &ex);
    ASSERT_GE(ex.count, 2);
    const float ct = std::cos(std::asin(b / ior)), f = mp_fresnel_dielectric(ct, 1.0f / ior);
    float total = ex.lost.x;
    for (int i = 0; i < ex.count; ++i) total += ex.weight[i].x;
    std::vector<float> w;
    for (int i = 0; i < ex.count; ++i) w.push_back(ex.weight[i].x);
    std::sort(w.rbegin(), w.rend());
    EXPECT_NEAR(w[0], 1.0f - f, 1e-3f);      // out at the first hit
    EXPECT_NEAR(w[1], (1.0f - f) * f, 1e-3f); // reflected once inside, out at the second
    // Dropped: paths under MP_REFRACT_MIN_WEIGHT and past MP_REFRACT_MAX_DEPTH.
    EXPECT_GT(total, 1.0f - 3.0f * MP_REFRACT_MIN_WEIGHT);
    EXPECT_LE(total, 1.0f + 1e-4f);
  }
}

// In a box, a ray entering the top at 80 degrees meets a side at 49
// degrees, past the critical angle of IOR 1.5 (41.8): a refraction lobe
// loses it there (Cycles' refraction BSDF has no reflection); glass
// reflects it all and it leaves through the bottom parallel to how it came.
TEST(RefractionTrace, TotalInternalReflectionInABox) {
  Proxy proxy(box(glm::vec3(-1.0f, -1.0f, -1.0f), glm::vec3(1.0f, 1.0f, 1.0f)));
  const float ior = 1.5f, a = 80.0f * kPi / 180.0f;
  const glm::vec3 d0(std::sin(a), 0.0f, -std::cos(a)), p(0.5f, 0.0f, 1.0f);
  const glm::vec3 t = refract(d0, glm::vec3(0.0f, 0.0f, 1.0f), 1.0f / ior);
  MpRefractExits ex;
  mp_refract_paths(&proxy.scene, p, t, 1e-4f, 1e-5f, ior, 0, glm::vec3(1.0f), &ex);
  EXPECT_EQ(ex.count, 0);
  mp_refract_paths(&proxy.scene, p, t, 1e-4f, 1e-5f, ior, 1, glm::vec3(1.0f), &ex);
  ASSERT_GE(ex.count, 1);
  // The strongest exit: through the bottom, mirrored in x by the side.
  int best = 0;
  for (int i = 1; i < ex.count; ++i)
    if (ex.weight[i].x > ex.weight[best].x) best = i;
  EXPECT_LT(angle_deg(ex.dir[best], glm::vec3(-d0.x, d0.y, d0.z)), 0.01f);
  const float ct = std::cos(std::asin(std::sin(a) / ior));
  EXPECT_NEAR(ex.weight[best].x, 1.0f - mp_fresnel_dielectric(ct, 1.0f / ior), 1e-4f);
}

// The proxy of a subdivided cube (built from its patches) against every
// triangle tried in turn, for rays from inside and outside; from its centre
// every ray leaves through a surface wound outwards.
TEST(RefractionTrace, PatchProxyMatchesBruteForce) {
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(mp::test::cube_mesh(mp::SubdivScheme::CatmullClark), glm::mat4(1.0f), buf);
  mp::share_patch_edges(buf, 0);
  const mp::RefractionProxies data = mp::build_refraction_proxies(buf, 1, {true});
  ASSERT_EQ(data.roots.size(), 1u);
  ASSERT_NE(data.roots[0], MP_REFRACT_NONE);
  const size_t tri_count = data.tris.size() / 6;
  EXPECT_GE(tri_count, buf.size() * 2);
  EXPECT_LE(tri_count, mp::kRefractionObjectTriangles);
  MpRefractScene sc{data.nodes.data(), data.tris.data(), data.roots[0]};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int hits = 0, from_centre = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 o = i % 2 ? glm::vec3(0.0f) : 3.0f * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 d(u(rng), u(rng), u(rng));
    if (!(glm::length(d) > 0.1f)) continue;
    d = glm::normalize(d);
    MpRefractHit h{};
    const int found = mp_refract_trace(&sc, o, d, 1e-6f, 1e30f, &h);
    float best = 1e30f;
    for (size_t k = 0; k < tri_count; ++k) {
      const glm::vec4* t = data.tris.data() + 6 * k;
      float tt, a, b;
      if (mp_refract_tri_hit(o, d, glm::vec3(t[0]), glm::vec3(t[1]), glm::vec3(t[2]), 1e-6f, best, &tt, &a, &b))
        best = tt;
    }
    ASSERT_EQ(found != 0, best < 1e30f) << "ray " << i;
    if (!found) continue;
    ++hits;
    EXPECT_FLOAT_EQ(h.t, best);
    if (i % 2) {
      ++from_centre;
      glm::vec3 n, ng;
      EXPECT_EQ(mp_refract_hit_normal(&sc, &h, d, &n, &ng), 0) << "leaving through an inward-wound triangle";
      EXPECT_LT(glm::dot(n, d), 0.0f);
    }
  }
  EXPECT_EQ(from_centre, 200);  // nothing escapes from inside a closed surface
  EXPECT_GT(hits, from_centre);
}

// A mesh collapsed to a point has no triangle to trace: no proxy (the shade
// falls back to the single lookup) rather than an empty tree.
TEST(RefractionTrace, CollapsedMeshGetsNoProxy) {
  mp::Mesh point = mp::test::cube_mesh(mp::SubdivScheme::CatmullClark);
  for (glm::vec3& q : point.points) q = glm::vec3(0.25f);
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(point, glm::mat4(1.0f), buf);
  mp::share_patch_edges(buf, 0);
  const mp::RefractionProxies data = mp::build_refraction_proxies(buf, 1, {true});
  EXPECT_EQ(data.roots[0], MP_REFRACT_NONE);
  EXPECT_TRUE(data.nodes.empty());
}

// Only refracting materials get a proxy, and programs are told apart by
// what the node compiler writes.
TEST(RefractionTrace, OnlyRefractingProgramsGetProxies) {
  const std::vector<float> no_values;
  EXPECT_TRUE(mp::program_refracts("  mp_add_glass_tinted(s, w, c, 0, 0.0f, 1.45f, 0);", no_values));
  EXPECT_TRUE(mp::program_refracts("  mp_add_refraction(s, w, 0, 0.0f, 1.45f, 0);", no_values));
  EXPECT_TRUE(mp::program_refracts("  p1.transmission = v7;\n", no_values));
  EXPECT_FALSE(mp::program_refracts("  p1.transmission = 0.0f;\n  p1.metallic = 1.0f;", no_values));
  // A node value (MP_PARAM) refracts unless the material's value is 0.
  EXPECT_FALSE(mp::program_refracts("  p1.transmission = MP_PARAM(1);\n", {0.5f, 0.0f}));
  EXPECT_TRUE(mp::program_refracts("  p1.transmission = MP_PARAM(0);\n", {0.5f, 0.0f}));
  EXPECT_TRUE(mp::program_refracts("  p1.transmission = MP_PARAM(1) * v2;\n", {0.5f, 0.0f}));
  mp::PatchBuffer buf;
  mp::append_subdiv_patches(mp::test::cube_mesh(mp::SubdivScheme::CatmullClark), glm::mat4(1.0f), buf);
  mp::share_patch_edges(buf, 0);
  const mp::RefractionProxies none = mp::build_refraction_proxies(buf, 1, {false});
  EXPECT_EQ(none.roots[0], MP_REFRACT_NONE);
  EXPECT_TRUE(none.tris.empty());
}

// Through a glass slab the world is seen along the view itself, only shifted
// sideways (its faces are parallel): rendered, a Refraction slab turned 25
// degrees to the view shows the pixel's own direction of a world whose red
// is a ramp in longitude. A slab the proxy does not know (a program naming
// its refraction in a way program_refracts misses falls back to one
// lookup as through a sphere) shows it bent: the test can tell.
namespace mp::test {
namespace {

class RefractionRenderTest : public SharedRendererTest {};

Scene slab_in_a_ramp(const std::string& surface) {
  Scene s = base_scene(64, 64, 4);
  s.lights.clear();
  s.camera.world_to_camera = glm::lookAt(glm::vec3(0, -5, 0), glm::vec3(0), glm::vec3(0, 0, 1));
  s.camera.fov_degrees = 45.0f;
  Mesh box = cube_mesh(SubdivScheme::None);
  box.object_to_world = glm::rotate(glm::mat4(1.0f), glm::radians(25.0f), glm::vec3(0, 0, 1)) *
                        glm::scale(glm::mat4(1.0f), glm::vec3(1.5f, 0.5f, 1.5f));
  s.meshes.push_back(box);
  s.materials[0].name = "glass";
  s.materials[0].program = 0;
  s.materials[0].program_shades = true;
  s.material_programs.push_back(
      {"glass", "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }\n"
                "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) { " + surface + " }\n"});
  s.world.width = 256, s.world.height = 128;
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 256; ++x) s.world.radiance.insert(s.world.radiance.end(), {2.0f * (x + 0.5f) / 256.0f, 0.2f, 0.2f, 1.0f});
  return s;
}

// The ramp's red along the world direction through pixel (px, py).
float ramp_red(int px, int py) {
  const float t = std::tan(glm::radians(22.5f));
  const glm::vec3 d(((px + 0.5f) / 32.0f - 1.0f) * t, 1.0f, (1.0f - (py + 0.5f) / 32.0f) * t);
  return 2.0f * (0.5f - std::atan2(d.y, d.x) / (2.0f * kPi));
}

}  // namespace

TEST_F(RefractionRenderTest, SlabShowsTheWorldAlongTheView) {
  const RenderResult r = renderer_->render(slab_in_a_ramp("mp_add_refraction(s, (float3)(1.0f), 0, 0.0f, 1.5f, 0);"));
  const RenderResult bent = renderer_->render(slab_in_a_ramp(
      "\n#define MP_JOIN(a, b) a##b\n MP_JOIN(mp_add_, refraction)(s, (float3)(1.0f), 0, 0.0f, 1.5f, 0);"));
  float worst = 0.0f, worst_bent = 0.0f;
  int inside = 0;
  for (int py = 22; py < 42; ++py)
    for (int px = 26; px < 38; ++px) {
      const size_t i = 4 * (size_t(py) * 64 + px);
      ASSERT_GT(r.rgba[i + 3], 0.999f) << "pixel " << px << ", " << py << " misses the slab";
      ++inside;
      worst = std::max(worst, std::abs(r.rgba[i] - ramp_red(px, py)));
      worst_bent = std::max(worst_bent, std::abs(bent.rgba[i] - ramp_red(px, py)));
    }
  EXPECT_EQ(inside, 240);
  EXPECT_LT(worst, 0.01f);       // the ramp changes by 0.0085 per pixel here
  EXPECT_GT(worst_bent, 0.05f);  // six pixels' worth of bending
}

// A slab squashed to no thickness (front and back faces coincide) and glass
// of IOR 0 or NaN: the paths end cleanly and every pixel stays finite.
TEST_F(RefractionRenderTest, DegenerateGlassRendersFinite) {
  Scene flat = slab_in_a_ramp("mp_add_glass(s, (float3)(1.0f), 0, 0.0f, 1.5f, 0);");
  flat.meshes[0].object_to_world = glm::rotate(glm::mat4(1.0f), glm::radians(25.0f), glm::vec3(0, 0, 1));
  for (glm::vec3& q : flat.meshes[0].points) q.y = 0.0f;
  for (const char* ior : {"0.0f", "NAN"}) {
    SCOPED_TRACE(ior);
    Scene odd = slab_in_a_ramp(std::string("mp_add_glass(s, (float3)(1.0f), 0, 0.0f, ") + ior + ", 0);");
    for (const Scene* sc : {&flat, &odd}) {
      const RenderResult r = renderer_->render(*sc);
      for (float v : r.rgba) ASSERT_TRUE(std::isfinite(v));
    }
  }
}

}  // namespace mp::test
