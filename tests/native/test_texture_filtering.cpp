// Filtered image lookups (kernels/textures/mp_tex_image.h): MIP levels that
// are exact box averages in linear colour, built alike on the device, and
// lookups over a footprint that average what it covers along its long axis
// while keeping detail across its short one.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "cl/device_session.h"
#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "textures/mp_tex_image.h"

namespace mp {
namespace {

// An image's texels with every MIP level, built on the host.
struct Mipped {
  DeviceImage im{};
  std::vector<glm::vec4> texels;
};

Mipped mipped(int w, int h, bool srgb, float (*value)(int x, int y)) {
  Mipped m;
  m.im = DeviceImage{0u, uint32_t(w), uint32_t(h), srgb ? 1u : 0u};
  m.texels.resize(size_t(mp_image_texel_count(m.im.width, m.im.height)));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float v = value(x, y);
      m.texels[size_t(y) * w + x] = glm::vec4(v, v, v, 1.0f);
    }
  for (uint32_t l = 1; l < mp_image_levels(m.im.width, m.im.height); ++l) {
    const DeviceImage from = mp_image_level(m.im, l - 1), to = mp_image_level(m.im, l);
    for (uint32_t y = 0; y < to.height; ++y)
      for (uint32_t x = 0; x < to.width; ++x)
        m.texels[to.offset + y * to.width + x] = l == 1 ? mp_image_first_level_texel(m.texels.data(), from, to, x, y)
                                                        : mp_image_reduce_texel(m.texels.data(), from, to, x, y);
  }
  return m;
}

float checker(int x, int y) { return float((x + y) % 2); }
float columns(int x, int) { return float(x % 2); }
float rows(int, int y) { return float(y % 2); }
float ramp(int x, int y) { return 0.01f * float(x) + 0.003f * float(y * y); }
float wave(int x, int y) { return 0.5f + 0.4f * std::sin(0.7f * float(x)) * std::cos(0.45f * float(y)); }

glm::vec4 lookup(const Mipped& m, float u, float v, glm::vec2 dx, glm::vec2 dy, int interpolation = MP_IMAGE_LINEAR) {
  return mp_tex_image_area(&m.im, 1u, m.texels.data(), 0, u, v, dx, dy, interpolation, MP_EXTENSION_REPEAT);
}

TEST(TextureFiltering, LevelsHalveDownToOneTexelAndAverageExactlyWhereSizesAreOdd) {
  EXPECT_EQ(mp_image_levels(1, 1), 1u);
  EXPECT_EQ(mp_image_levels(11, 7), 4u);  // 11x7, 5x3, 2x1, 1x1
  EXPECT_EQ(mp_image_texel_count(11, 7), 77u + 15u + 2u + 1u);
  EXPECT_EQ(mp_image_levels(1024, 16), 11u);
  const Mipped m = mipped(11, 7, false, ramp);
  const DeviceImage l1 = mp_image_level(m.im, 1), l2 = mp_image_level(m.im, 2), l3 = mp_image_level(m.im, 3);
  // Level 2's texel 1 covers x in [2.5, 5) and all three rows of level 1.
  double sum = 0.0;
  for (uint32_t y = 0; y < 3; ++y) {
    const glm::vec4* row = &m.texels[l1.offset + y * l1.width];
    sum += 0.5 * row[2].x + row[3].x + row[4].x;
  }
  EXPECT_NEAR(m.texels[l2.offset + 1].x, float(sum / 7.5), 1e-6f);
  EXPECT_NEAR(m.texels[l3.offset].x, 0.5f * (m.texels[l2.offset].x + m.texels[l2.offset + 1].x), 1e-6f);
}

float encoded_step(int x, int) { return x < 4 ? 0.0f : 1.0f; }

double srgb_decoded(double e) { return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4); }

TEST(TextureFiltering, TheFirstLevelIsTheMeanOfWhatTheLookupShowsDecoded) {
  // 8 x 2 sRGB texels, encoded 0 then 1 from x = 4: the Linear lookup ramps
  // from texel centre 3.5 to 4.5, and Cycles decodes after interpolating,
  // so level 1's texel over [2, 4) holds the mean of the decoded ramp's
  // first half, integrated here on its own.
  const Mipped m = mipped(8, 2, true, encoded_step);
  double integral = 0.0;
  const int steps = 100000;
  for (int i = 0; i < steps; ++i) integral += srgb_decoded(0.5 * (i + 0.5) / steps) * 0.5 / steps;
  const DeviceImage l1 = mp_image_level(m.im, 1);
  EXPECT_NEAR(m.texels[l1.offset + 1].x, float(integral / 2.0), 0.002f);
  EXPECT_EQ(m.texels[l1.offset].x, 0.0f);
  EXPECT_NEAR(m.texels[l1.offset + 3].x, 1.0f, 2e-5f);  // the levels' decode is within 1.8e-5
  // Decoded before it is averaged: the mean of linear 0 and 1 over the
  // whole image, less the ramp's share, not decode(mean of the codes).
  EXPECT_GT(m.texels[mp_image_level(m.im, 3).offset].x, 0.45f);
}

TEST(TextureFiltering, ColourIsWeightedByAlpha) {
  // A transparent texel's colour does not bleed into the average.
  std::vector<glm::vec4> t = {glm::vec4(1.0f, 0.0f, 0.0f, 1.0f), glm::vec4(0.0f, 1.0f, 0.0f, 0.0f), glm::vec4(0.0f)};
  const DeviceImage a{0u, 2u, 1u, 0u}, b{2u, 1u, 1u, 0u};
  const glm::vec4 c = mp_image_reduce_texel(t.data(), a, b, 0, 0);
  EXPECT_NEAR(c.x, 1.0f, 1e-6f);
  EXPECT_NEAR(c.y, 0.0f, 1e-6f);
  EXPECT_NEAR(c.w, 0.5f, 1e-6f);
}

TEST(TextureFiltering, AFootprintWithinATexelIsTheUnfilteredLookup) {
  const Mipped m = mipped(64, 64, true, ramp);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uv(-0.5f, 1.5f), d(-0.9f / 64.0f, 0.9f / 64.0f);
  for (int i = 0; i < 200; ++i) {
    const float u = uv(rng), v = uv(rng);
    const glm::vec2 dx(d(rng) * 0.5f, d(rng) * 0.5f), dy(d(rng) * 0.5f, d(rng) * 0.5f);  // under 0.9 texel
    for (int interpolation : {MP_IMAGE_LINEAR, MP_IMAGE_CUBIC, MP_IMAGE_CLOSEST}) {
      const glm::vec4 plain = mp_tex_image(&m.im, 1u, m.texels.data(), 0, u, v, interpolation, MP_EXTENSION_REPEAT);
      EXPECT_EQ(lookup(m, u, v, dx, dy, interpolation), plain);
    }
  }
}

TEST(TextureFiltering, WideFootprintsAverageWhatTheyCover) {
  const Mipped m = mipped(64, 64, false, checker);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uv(0.0f, 1.0f), turn(0.0f, 6.2831853f);
  for (int i = 0; i < 200; ++i) {
    // Isotropic footprints 4 to 32 texels wide, turned any way.
    const float width = (4.0f + 28.0f * uv(rng)) / 64.0f, a = turn(rng);
    const glm::vec2 dx = width * glm::vec2(std::cos(a), std::sin(a)), dy = width * glm::vec2(-std::sin(a), std::cos(a));
    EXPECT_NEAR(lookup(m, uv(rng), uv(rng), dx, dy).x, 0.5f, 0.02f);
  }
}

TEST(TextureFiltering, LongFootprintsKeepDetailAcrossTheirShortAxis) {
  // 1-texel stripes: a footprint 12 texels long along the stripes and 0.9
  // across (within MP_IMAGE_MAX_ANISOTROPY) reads the stripe it lies in; the
  // same footprint across the stripes averages them.
  const Mipped along = mipped(64, 64, false, rows), across = mipped(64, 64, false, columns);
  const glm::vec2 dx(12.0f / 64.0f, 0.0f), dy(0.0f, 0.9f / 64.0f);
  for (int y = 0; y < 64; ++y) {
    const float v = (float(y) + 0.5f) / 64.0f, u = 0.3f + 0.01f * float(y);
    EXPECT_NEAR(lookup(along, u, v, dx, dy).x, float(y % 2), 1e-4f) << "row " << y;
    EXPECT_NEAR(lookup(across, u, v, dx, dy).x, 0.5f, 0.05f) << "row " << y;
  }
}

TEST(TextureFiltering, TheResultChangesSmoothlyAsTheFootprintGrows) {
  const Mipped m = mipped(64, 64, true, wave);
  glm::vec4 last = lookup(m, 0.37f, 0.61f, glm::vec2(0.0f), glm::vec2(0.0f));
  for (float w = 0.05f; w < 40.0f; w *= 1.02f) {
    const glm::vec4 c = lookup(m, 0.37f, 0.61f, glm::vec2(w / 64.0f, 0.0f), glm::vec2(0.0f, 0.6f * w / 64.0f));
    EXPECT_LT(std::abs(c.x - last.x), 0.02f) << "footprint " << w;
    last = c;
  }
}

TEST(TextureFiltering, TheDeviceBuildsTheSameLevels) {
  Scene scene;
  Image image;
  image.name = "odd";
  image.width = 37, image.height = 10;
  image.srgb = true;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) image.pixels.push_back(glm::vec4(ramp(x, y), checker(x, y), 0.25f, 0.5f + 0.05f * float(x % 10)));
  scene.images.push_back(image);
  const HostSceneData host = prepare_scene_data(scene);
  ASSERT_EQ(host.device_texels, size_t(mp_image_texel_count(37, 10)));
  DeviceSession session("");
  SceneBuffers buffers = upload_scene_data(session, host);
  std::vector<glm::vec4> device(host.device_texels);
  session.queue().enqueueReadBuffer(buffers.texels, CL_TRUE, 0, device.size() * sizeof(glm::vec4), device.data());
  std::vector<glm::vec4> texels(host.device_texels);
  std::copy(image.pixels.begin(), image.pixels.end(), texels.begin());
  const DeviceImage im = host.images[0];
  for (uint32_t l = 1; l < mp_image_levels(im.width, im.height); ++l) {
    const DeviceImage from = mp_image_level(im, l - 1), to = mp_image_level(im, l);
    for (uint32_t i = 0; i < to.width * to.height; ++i)
      texels[to.offset + i] = l == 1 ? mp_image_first_level_texel(texels.data(), from, to, i % to.width, i / to.width)
                                     : mp_image_reduce_texel(texels.data(), from, to, i % to.width, i / to.width);
  }
  for (size_t i = 0; i < texels.size(); ++i)
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(device[i][c], texels[i][c], 1e-5f) << "texel " << i << " channel " << c;
}

}  // namespace
}  // namespace mp
