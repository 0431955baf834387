// The world's light as lights (pipeline/world/world_lighting.h), against
// analytic results: a uniform world's irradiance and a point-like sun's.
#include <gtest/gtest.h>

#include <cmath>

#include "cl/device_session.h"
#include "micropoly/error.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "closures/mp_world.h"
#include "pipeline/world/world_lighting.h"

namespace mp {
namespace {

WorldMap uniform_map(int w, const glm::vec3& radiance) {
  WorldMap m;
  m.width = w, m.height = w / 2;
  m.radiance.assign(size_t(m.width) * size_t(m.height), radiance);
  return m;
}

TEST(WorldLighting, UniformWorldGivesItsRadianceAsIrradianceOverPi) {
  // A uniform radiance L gives irradiance pi L on every normal: E / pi = L.
  const WorldMap m = uniform_map(64, glm::vec3(0.5f, 1.0f, 2.0f));
  const auto sh = world_irradiance_sh(m);
  for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(-1, 2, -3))}) {
    const glm::vec3 e = eval_irradiance_sh(sh, n);
    EXPECT_NEAR(e.x, 0.5f, 2e-3f);
    EXPECT_NEAR(e.y, 1.0f, 4e-3f);
    EXPECT_NEAR(e.z, 2.0f, 8e-3f);
  }
}

TEST(WorldLighting, UpperHemisphereLightsUpFacingNormalsOnly) {
  // Radiance 1 above the horizon, 0 below: E(up) = pi, E(down) = 0,
  // E(sideways) = pi / 2. Order-2 harmonics are within about 10% of these.
  WorldMap m = uniform_map(128, glm::vec3(1.0f));
  for (int y = 0; y < m.height / 2; ++y)
    for (int x = 0; x < m.width; ++x) m.radiance[size_t(y) * m.width + x] = glm::vec3(0.0f);
  const auto sh = world_irradiance_sh(m);
  EXPECT_NEAR(eval_irradiance_sh(sh, glm::vec3(0, 0, 1)).x, 1.0f, 0.1f);
  EXPECT_NEAR(eval_irradiance_sh(sh, glm::vec3(0, 0, -1)).x, 0.0f, 0.1f);
  EXPECT_NEAR(eval_irradiance_sh(sh, glm::vec3(1, 0, 0)).x, 0.5f, 0.05f);
}

// The GGX-prefiltered radiance of a map around unit n with view = normal,
// by quadrature over the map's texels: sum L(l) D(h) (n.l) dOmega over the
// same weights without L (the prefiltering world_glossy_maps approximates).
glm::vec3 prefiltered_by_quadrature(const WorldMap& m, const glm::vec3& n, float roughness) {
  const double a2 = std::pow(double(roughness), 4.0), pi = 3.14159265358979;
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < m.height; ++y) {
    const double sa = (std::sin(pi * ((y + 1.0) / m.height - 0.5)) - std::sin(pi * (double(y) / m.height - 0.5))) *
                      2.0 * pi / m.width;
    for (int x = 0; x < m.width; ++x) {
      const glm::dvec3 l(world_map_direction(m.width, m.height, float(x), float(y)));
      const double nl = glm::dot(glm::dvec3(n), l);
      if (nl <= 0.0) continue;
      const double nh = glm::dot(glm::dvec3(n), glm::normalize(l + glm::dvec3(n)));
      const double q = nh * nh * (a2 - 1.0) + 1.0;
      const double w = a2 / (pi * q * q) * nl * sa;
      sum += glm::dvec3(m.radiance[size_t(y) * m.width + x]) * w;
      weight += w;
    }
  }
  return glm::vec3(sum / weight);
}

glm::vec3 glossy_level_at(const std::vector<glm::vec4>& maps, int k, const glm::vec3& d) {
  return mp_world_glossy_level(maps.data(), k, d);
}

TEST(WorldLighting, GlossyMapsOfAUniformWorldAreUniform) {
  const auto maps = world_glossy_maps(uniform_map(256, glm::vec3(0.25f, 0.5f, 1.0f)));
  for (int k = 0; k < MP_WORLD_GLOSSY_LEVELS; ++k)
    for (const glm::vec3 d : {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(-1, 2, -3))}) {
      const glm::vec3 c = glossy_level_at(maps, k, d);
      EXPECT_NEAR(c.x, 0.25f, 1e-3f) << k;
      EXPECT_NEAR(c.z, 1.0f, 4e-3f) << k;
    }
}

TEST(WorldLighting, GlossyMapsMatchTheLobeIntegratedByQuadrature) {
  // A sky of radiance 1 above the horizon and 0 below: near the horizon
  // the lobe sees both, by an amount that grows with the roughness.
  WorldMap m = uniform_map(256, glm::vec3(1.0f));
  for (int y = 0; y < m.height / 2; ++y)
    for (int x = 0; x < m.width; ++x) m.radiance[size_t(y) * m.width + x] = glm::vec3(0.0f);
  const auto maps = world_glossy_maps(m);
  for (int k : {2, 3, 5, 8}) {
    const float roughness = float(k) / float(MP_WORLD_GLOSSY_LEVELS - 1);
    for (float elevation : {-0.3f, -0.1f, 0.05f, 0.2f, 0.6f}) {
      const glm::vec3 d(std::cos(elevation), 0.3f * std::cos(elevation), std::sin(elevation));
      const glm::vec3 n = glm::normalize(d);
      const float expect = prefiltered_by_quadrature(m, n, roughness).x;
      EXPECT_NEAR(glossy_level_at(maps, k, n).x, expect, 0.04f) << "roughness " << roughness << " elevation "
                                                                 << elevation;
    }
  }
}

TEST(WorldLighting, DevicePrefilterMatchesTheHostTexelByTexel) {
  // A map with detail at every scale (a bright small sun, a coloured
  // horizon band, a gradient) and of a width that is not a power of two,
  // so every mip level, the odd halvings and the wrap are read. The device
  // (kernels/stages/world_glossy.cl) and the host run the same texel
  // function; they may differ only by float rounding and the device's
  // transcendental functions.
  WorldMap m;
  m.width = 200, m.height = 100;
  m.radiance.resize(size_t(m.width) * size_t(m.height));
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      glm::vec3 c(0.1f + 0.8f * float(y) / m.height, 0.3f, 0.2f + 0.5f * float(x) / m.width);
      if (y >= 45 && y < 52) c += glm::vec3(2.0f, 1.0f, 0.1f);
      if (std::abs(x - 150) <= 1 && std::abs(y - 80) <= 1) c += glm::vec3(400.0f);
      m.radiance[size_t(y) * m.width + x] = c;
    }
  const std::vector<glm::vec4> host = world_glossy_maps(m);
  DeviceSession session("");
  const cl::Buffer maps = prefilter_world_glossy(session, m);
  std::vector<glm::vec4> device(host.size());
  session.queue().enqueueReadBuffer(maps, CL_TRUE, 0, device.size() * sizeof(glm::vec4), device.data());
  double worst = 0.0;
  for (size_t i = 0; i < host.size(); ++i)
    for (int c = 0; c < 4; ++c)
      worst = std::max(worst, std::fabs(double(device[i][c]) - host[i][c]) / std::max(1.0, double(std::fabs(host[i][c]))));
  EXPECT_LT(worst, 1e-3) << "largest relative difference";
  // Not a trivially equal pair: the levels differ from one another.
  EXPECT_GT(std::fabs(host[size_t(mp_world_glossy_offset(1))].x - host[size_t(mp_world_glossy_offset(8))].x), 0.01f);
  // An empty map gives zeros.
  const cl::Buffer none = prefilter_world_glossy(session, WorldMap{});
  session.queue().enqueueReadBuffer(none, CL_TRUE, 0, device.size() * sizeof(glm::vec4), device.data());
  for (const glm::vec4& v : device) ASSERT_EQ(v, glm::vec4(0.0f));
}

TEST(WorldLighting, MapCoordinatesRoundTrip) {
  for (const glm::vec3 d : {glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::normalize(glm::vec3(0.3f, -0.4f, 0.8f))}) {
    const glm::vec2 uv = world_map_uv(d);
    const glm::vec3 back = world_map_direction(1000, 500, uv.x * 1000 - 0.5f, uv.y * 500 - 0.5f);
    EXPECT_NEAR(glm::dot(back, d), 1.0f, 1e-5f);
  }
  // +X faces the map's centre, +Z its top row (Cycles' equirectangular).
  EXPECT_NEAR(world_map_uv(glm::vec3(1, 0, 0)).x, 0.5f, 1e-6f);
  EXPECT_NEAR(world_map_uv(glm::vec3(0, 0, 1)).y, 1.0f, 1e-6f);
}

TEST(WorldLighting, MedianCutFindsTheSunAndKeepsTheLight) {
  // A dim sky and one bright texel: the cut gives every region an equal
  // share of the light, so one small region holds the sun, pointing at it.
  WorldMap m = uniform_map(128, glm::vec3(0.01f));
  const int sx = 40, sy = 50;
  m.radiance[size_t(sy) * m.width + sx] = glm::vec3(5000.0f);
  const glm::vec3 sun = world_map_direction(m.width, m.height, float(sx), float(sy));
  const auto regions = median_cut(m, 8);
  ASSERT_EQ(regions.size(), 8u);
  double total = 0.0, expected = 0.0;
  for (const WorldRegion& r : regions) total += r.light.x;
  for (int y = 0; y < m.height; ++y) {
    const double lo = M_PI * (double(y) / m.height - 0.5), hi = M_PI * (double(y + 1) / m.height - 0.5);
    const double sa = (std::sin(hi) - std::sin(lo)) * 2.0 * M_PI / m.width;
    for (int x = 0; x < m.width; ++x) expected += m.radiance[size_t(y) * m.width + x].x * sa;
  }
  EXPECT_NEAR(total, expected, 1e-4 * expected);
  float best = -1.0f;
  for (const WorldRegion& r : regions) best = std::max(best, glm::dot(r.direction, sun));
  EXPECT_GT(best, 0.999f);
  // The probes and the environment light follow.
  const auto lights = world_lights(m, World{}, 8);
  ASSERT_FALSE(lights.empty());
  EXPECT_EQ(lights.back().type, Light::Type::Environment);
  EXPECT_EQ(lights.back().irradiance_sh.size(), 27u);
  for (size_t i = 0; i + 1 < lights.size(); ++i) EXPECT_TRUE(lights[i].world_probe);
}

}  // namespace
}  // namespace mp

namespace mp {
namespace {

// A broken world is refused with a message naming the world, before any
// device work.
TEST(WorldLighting, BadWorldsAreRefusedCleanly) {
  auto refused = [](const Scene& s) {
    try {
      validate_scene(s);
    } catch (const Error& e) {
      return std::string(e.what()).find("world") != std::string::npos;
    }
    return false;
  };
  Scene program_missing;
  program_missing.world.program = 3;
  EXPECT_TRUE(refused(program_missing));
  Scene size_mismatch;
  size_mismatch.world.width = 4, size_mismatch.world.height = 2;
  size_mismatch.world.radiance.assign(7, 1.0f);
  EXPECT_TRUE(refused(size_mismatch));
  Scene nan_texel;
  nan_texel.world.width = 2, nan_texel.world.height = 1;
  nan_texel.world.radiance.assign(8, 1.0f);
  nan_texel.world.radiance[5] = std::nanf("");
  EXPECT_TRUE(refused(nan_texel));
  Scene too_many_probes;
  too_many_probes.world.width = 2, too_many_probes.world.height = 1;
  too_many_probes.world.radiance.assign(8, 1.0f);
  too_many_probes.settings.world_probes = 1000;
  EXPECT_TRUE(refused(too_many_probes));
  Scene fine = too_many_probes;
  fine.settings.world_probes = 8;
  EXPECT_FALSE(refused(fine));
}

}  // namespace
}  // namespace mp
