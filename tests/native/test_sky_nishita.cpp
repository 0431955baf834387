// The Sky Texture's physical skies (sky/sky_nishita.h) through the
// lookup the kernels run (sky_radiance): what Rayleigh and Mie scattering
// must give whatever the implementation (a blue zenith, a red sunset, a sky
// symmetric about the sun), the sun disc's light against the irradiance it
// stands for, and the light spread for baked maps against the disc's.
#include <gtest/gtest.h>

#include <cmath>

#include "sky/sky_nishita.h"

namespace mp {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr SkyModel kModels[] = {SkyModel::Nishita, SkyModel::SingleScattering, SkyModel::MultipleScattering};

float radians(float degrees) { return degrees * kPi / 180.0f; }

SkyParameters sky(SkyModel model, float elevation_degrees, float rotation_degrees = 0.0f) {
  SkyParameters p;
  p.model = model;
  p.sun_elevation = radians(elevation_degrees);
  p.sun_rotation = radians(rotation_degrees);
  p.altitude = 100.0f;
  return p;
}

// Blender's world direction at an elevation and a compass azimuth (degrees
// clockwise from +Y, as the node's Sun Rotation turns).
glm::vec3 direction(float elevation_degrees, float azimuth_degrees) {
  float e = radians(elevation_degrees), a = radians(azimuth_degrees);
  return {std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)};
}

struct Sky {
  SkyTexture texture;
  SkyLookup lookup;
};

Sky make(const SkyParameters& p, float spread = 0.0f) { return {sky_texture(p), sky_lookup_parameters(p, spread)}; }

glm::vec3 radiance(const Sky& s, const glm::vec3& d) { return sky_radiance(s.texture, s.lookup, d); }

TEST(SkyNishita, TexturesHaveCyclesSizeAndFinitePositiveSky) {
  for (SkyModel model : kModels) {
    SkyTexture t = sky_texture(sky(model, 30.0f));
    glm::ivec2 size = sky_texture_size(model);
    ASSERT_EQ(t.width, size.x);
    ASSERT_EQ(t.height, size.y);
    ASSERT_EQ(t.texels.size(), size_t(t.width) * t.height);
    EXPECT_EQ(t.width, 512);
    EXPECT_EQ(t.height, model == SkyModel::Nishita ? 128 : 256);
    // Rows from the horizon up: the whole texture before 5.0, its upper half after.
    int first_sky_row = model == SkyModel::Nishita ? 0 : t.height / 2;
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x) {
        const glm::vec4& c = t.texels[size_t(y) * t.width + x];
        ASSERT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z)) << x << ", " << y;
        ASSERT_EQ(c.w, 1.0f);
        if (y >= first_sky_row) ASSERT_GT(c.y, 0.0f) << "model " << int(model) << " texel " << x << ", " << y;
      }
  }
}

TEST(SkyNishita, ZenithIsBlueAtMidday) {
  for (SkyModel model : kModels) {
    Sky s = make(sky(model, 60.0f));
    glm::vec3 zenith = radiance(s, {0.0f, 0.0f, 1.0f});
    EXPECT_GT(zenith.z, 1.5f * zenith.x) << "model " << int(model) << ": " << zenith.x << " " << zenith.z;
    EXPECT_GT(zenith.z, zenith.y) << "model " << int(model);
  }
}

TEST(SkyNishita, SunsetIsRedderThanMidday) {
  for (SkyModel model : kModels) {
    // The sun's disc and the sky just above the horizon towards it.
    Sky noon = make(sky(model, 60.0f)), sunset = make(sky(model, 2.0f));
    glm::vec3 disc_noon = radiance(noon, direction(60.0f, 0.0f)), disc_sunset = radiance(sunset, direction(2.0f, 0.0f));
    EXPECT_GT(disc_sunset.x / disc_sunset.z, 2.0f * disc_noon.x / disc_noon.z) << "model " << int(model);
    glm::vec3 sky_noon = radiance(noon, direction(5.0f, 0.0f)), sky_sunset = radiance(sunset, direction(5.0f, 10.0f));
    EXPECT_GT(sky_sunset.x / sky_sunset.z, 1.5f * sky_noon.x / sky_noon.z) << "model " << int(model);
    // And the sun at noon is much brighter than at sunset.
    EXPECT_GT(disc_noon.y, 2.0f * disc_sunset.y) << "model " << int(model);
  }
}

TEST(SkyNishita, SkyIsSymmetricAboutTheSunsAzimuth) {
  for (SkyModel model : kModels) {
    const float sun_azimuth = 40.0f;
    Sky s = make(sky(model, 25.0f, sun_azimuth));
    for (float elevation : {1.0f, 10.0f, 30.0f, 70.0f})
      for (float offset : {5.0f, 30.0f, 90.0f, 160.0f}) {
        glm::vec3 a = radiance(s, direction(elevation, sun_azimuth + offset));
        glm::vec3 b = radiance(s, direction(elevation, sun_azimuth - offset));
        EXPECT_NEAR(a.y, b.y, 0.01f * a.y) << "model " << int(model) << " at " << elevation << ", " << offset;
      }
    // ... and the side towards the sun is the brighter one.
    EXPECT_GT(radiance(s, direction(20.0f, sun_azimuth + 10.0f)).y,
              1.5f * radiance(s, direction(20.0f, sun_azimuth + 180.0f)).y)
        << "model " << int(model);
  }
}

TEST(SkyNishita, SunDiscCarriesTheSunsIrradiance) {
  for (SkyModel model : kModels) {
    // The disc's radiance is irradiance over its solid angle, so its light
    // (the integral over the disc) does not depend on its size; without an
    // atmosphere nor on the sun's height.
    SkyParameters small = sky(model, 40.0f), large = small, vacuum = small, vacuum_high = small;
    large.sun_size = radians(3.0f);
    vacuum.air = vacuum.dust = vacuum.ozone = 0.0f;
    vacuum_high = vacuum;
    vacuum_high.sun_elevation = radians(85.0f);
    glm::vec3 f_small = sky_lookup_parameters(small).sun_flux, f_large = sky_lookup_parameters(large).sun_flux;
    EXPECT_NEAR(f_large.y, f_small.y, 0.01f * f_small.y) << "model " << int(model);
    glm::vec3 f_vacuum = sky_lookup_parameters(vacuum).sun_flux, f_high = sky_lookup_parameters(vacuum_high).sun_flux;
    EXPECT_NEAR(f_vacuum.y, f_high.y, 1e-3f * f_high.y) << "model " << int(model);
    // The atmosphere takes some of it.
    EXPECT_LT(f_small.y, 0.95f * f_vacuum.y) << "model " << int(model);
    // Limb darkening 1 - 0.6 (1 - cos) averages 0.8 over the disc: the
    // light is 0.8 of the disc's solid angle times its centre radiance.
    SkyLookup l = sky_lookup_parameters(vacuum);
    float half = 0.5f * l.sun_diameter, solid_angle = 2.0f * kPi * (1.0f - std::cos(half));
    glm::vec3 centre = 0.5f * (l.sun_bottom + l.sun_top);
    EXPECT_NEAR(l.sun_flux.y, 0.8f * solid_angle * centre.y, 2e-3f * l.sun_flux.y) << "model " << int(model);
    // Sun Intensity scales it.
    SkyParameters bright = small;
    bright.sun_intensity = 3.0f;
    EXPECT_NEAR(sky_lookup_parameters(bright).sun_flux.y, 3.0f * f_small.y, 1e-3f * f_small.y);
  }
}

TEST(SkyNishita, SpreadSunKeepsTheDiscsLightOnABakedMap) {
  // A 512 x 256 equirectangular map sampled at texel centres, as the world
  // is baked: the sky with the spread sun minus the sky without a disc,
  // summed with each texel's solid angle, is the disc's light.
  const int w = 512, h = 256;
  const float spread = 2.5f * 2.0f * kPi / w;
  for (SkyModel model : kModels)
    for (float elevation : {12.0f, 35.0f, 63.0f}) {
      SkyParameters p = sky(model, elevation, 150.0f), no_disc = p;
      no_disc.sun_disc = false;
      Sky with = make(p, spread);
      SkyLookup without = sky_lookup_parameters(no_disc);
      glm::dvec3 sum(0.0);
      for (int y = 0; y < h; ++y) {
        float e = kPi * ((y + 0.5f) / h - 0.5f), solid_angle = std::cos(e) * (2.0f * kPi / w) * (kPi / h);
        for (int x = 0; x < w; ++x) {
          float a = 2.0f * kPi * (x + 0.5f) / w;
          glm::vec3 d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
          sum += glm::dvec3(radiance(with, d) - sky_radiance(with.texture, without, d)) * double(solid_angle);
        }
      }
      // The disc's light in linear Rec.709 (the lookup's colour space).
      const glm::vec3 f = with.lookup.sun_flux;
      const double y709 = 0.2126729 * sum.x + 0.7151522 * sum.y + 0.0721750 * sum.z;
      EXPECT_NEAR(y709, f.y, 0.015 * f.y) << "model " << int(model) << " sun at " << elevation;
    }
}

TEST(SkyNishita, SunPositionWrapsAsCycles) {
  // 100 degrees up is 80 degrees up on the other side.
  SkyLookup over = sky_lookup_parameters(sky(SkyModel::Nishita, 100.0f, 30.0f));
  SkyLookup back = sky_lookup_parameters(sky(SkyModel::Nishita, 80.0f, 210.0f));
  EXPECT_NEAR(over.sun_elevation, back.sun_elevation, 1e-5f);
  EXPECT_NEAR(std::cos(over.sun_rotation), std::cos(back.sun_rotation), 1e-5f);
  EXPECT_NEAR(std::sin(over.sun_rotation), std::sin(back.sun_rotation), 1e-5f);
  // The disc is where the node points it: azimuth clockwise from +Y.
  Sky s = make(sky(SkyModel::Nishita, 30.0f, 90.0f));
  EXPECT_GT(radiance(s, direction(30.0f, 90.0f)).y, 1e4f * radiance(s, direction(30.0f, 92.0f)).y);
}

TEST(SkyNishita, GroundFadesToBlackBeforeBlender5) {
  Sky s = make(sky(SkyModel::Nishita, 30.0f));
  glm::vec3 horizon = radiance(s, direction(0.0f, 180.0f)), below = radiance(s, direction(-10.0f, 180.0f));
  EXPECT_LT(below.y, horizon.y * std::pow(1.0f - 2.5f * std::sin(radians(10.0f)), 3.0f) * 1.01f);
  EXPECT_GT(below.y, 0.0f);
  EXPECT_EQ(radiance(s, direction(-30.0f, 180.0f)).y, 0.0f);
  // A sun below the horizon shows no disc.
  Sky night = make(sky(SkyModel::Nishita, -5.0f));
  EXPECT_LT(radiance(night, direction(-5.0f, 0.0f)).y, 1.0f);
}

}  // namespace
}  // namespace mp
