// Blender 4.x's random-walk subsurface as Micropoly shades it
// (kernels/closures/mp_subsurface.h): Lambert scaled by what Cycles' walk returns
// from a thick slab, read from a table measured on a grid of albedo, view
// cosine, entry roughness and IOR (scripts/tables/subsurface_albedo_cycles.py).
//
// The reference values below were measured from Cycles 4.5 in separate
// renders, at IORs, albedos and view angles off the table's grid: a slab of
// one Color under a sun of strength pi straight down, an orthographic
// camera at the view angle, 256 samples over 32 x 32 pixels, no bounces.
// Interpolating the table must land within the renders' noise and the
// table's resolution.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/mp_compat.h"
#include "closures/mp_subsurface.h"

namespace {


struct CyclesSlab {
  float ior, roughness, view_degrees;
  float albedo[3], ratio[3];  // ratio returned / Color
};

const CyclesSlab kCycles[] = {
    {1.4f, 1.0f, 0.0f, {0.1f, 0.45f, 0.8f}, {0.8065f, 0.8865f, 0.9697f}},
    {1.4f, 1.0f, 45.0f, {0.1f, 0.45f, 0.8f}, {0.9395f, 0.9736f, 1.0029f}},
    {1.4f, 1.0f, 70.0f, {0.1f, 0.45f, 0.8f}, {1.1832f, 1.1123f, 1.0478f}},
    {2.0f, 1.0f, 0.0f, {0.1f, 0.45f, 0.8f}, {0.8434f, 0.9110f, 0.9792f}},
    {2.0f, 1.0f, 45.0f, {0.1f, 0.45f, 0.8f}, {0.9634f, 0.9861f, 1.0066f}},
    {2.0f, 1.0f, 70.0f, {0.1f, 0.45f, 0.8f}, {1.1628f, 1.0983f, 1.0423f}},
    {1.4f, 0.25f, 0.0f, {0.1f, 0.45f, 0.8f}, {0.7858f, 0.8714f, 0.9637f}},
    {1.4f, 0.25f, 45.0f, {0.1f, 0.45f, 0.8f}, {0.8665f, 0.9266f, 0.9857f}},
    {1.4f, 0.25f, 70.0f, {0.1f, 0.45f, 0.8f}, {0.9951f, 1.0069f, 1.0145f}},
    {1.4f, 0.0f, 45.0f, {0.1f, 0.45f, 0.8f}, {0.8503f, 0.9160f, 0.9817f}},
    {1.4f, 0.0f, 70.0f, {0.1f, 0.45f, 0.8f}, {0.9201f, 0.9624f, 0.9994f}},
};

float3 ratio_of(const CyclesSlab& c, int model = MP_SSS_WALK) {
  float nv = std::cos(c.view_degrees * 3.14159265f / 180.0f);
  return mp_subsurface_ratio(model, float3(c.albedo[0], c.albedo[1], c.albedo[2]), float3(0.1f), nv, c.roughness,
                             c.ior);
}

TEST(SubsurfaceTest, TheTableMatchesCyclesOffItsGrid) {
  float worst = 0.0f;
  for (const CyclesSlab& c : kCycles) {
    float3 r = ratio_of(c);
    for (int k = 0; k < 3; ++k) {
      float error = std::fabs(r[k] - c.ratio[k]) / c.ratio[k];
      worst = std::fmax(worst, error);
      EXPECT_LT(error, 0.025f) << "IOR " << c.ior << " roughness " << c.roughness << " view " << c.view_degrees
                               << " albedo " << c.albedo[k] << ": table " << r[k] << ", Cycles " << c.ratio[k];
    }
  }
  std::printf("worst relative difference to Cycles: %.4f\n", worst);
}

// The same renders tell Lambert (a ratio of 1, what Blender 3.x's walk
// returns) from Cycles 4.x's walk: the table must do far better than it.
TEST(SubsurfaceTest, LambertMissesWhatTheWalkReturns) {
  float table = 0.0f, lambert = 0.0f;
  for (const CyclesSlab& c : kCycles) {
    float3 r = ratio_of(c), one = ratio_of(c, MP_SSS_LAMBERT);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(one[k], 1.0f);
      table += std::fabs(r[k] - c.ratio[k]);
      lambert += std::fabs(1.0f - c.ratio[k]);
    }
  }
  EXPECT_LT(table * 5.0f, lambert) << "table " << table << ", Lambert " << lambert;
}

// Indexing: at the grid's own points the lookup returns the table's entry
// for that IOR, roughness, view cosine and albedo (axes in that order).
TEST(SubsurfaceTest, GridPointsReadTheirOwnEntry) {
  const float etas[] = {0.25f, 0.4375f, 0.625f, 0.8125f, 1.0f};
  const float cosines[] = {0.05f, 0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 1.0f};
  for (int e = 0; e < MP_SSS_ETAS; ++e)
    for (int k = 0; k < MP_SSS_ROUGHNESS; ++k)
      for (int c = 0; c < MP_SSS_COSINES; c += 4)
        for (int a = 0; a < MP_SSS_ALBEDOS; a += 3) {
          float albedo = mp_sss_albedo_axis[a];
          float3 r = mp_subsurface_ratio(MP_SSS_WALK, float3(albedo), float3(1.0f), cosines[c], 0.25f * k,
                                         1.0f / etas[e]);
          int i = ((e * MP_SSS_ROUGHNESS + k) * MP_SSS_COSINES + c) * MP_SSS_ALBEDOS + a;
          ASSERT_NEAR(r.x, mp_sss_walk[i], 1e-5f) << e << " " << k << " " << c << " " << a;
          float3 s = mp_subsurface_ratio(MP_SSS_SKIN, float3(albedo), float3(1.0f), cosines[c], 0.25f * k,
                                         1.0f / etas[e]);
          ASSERT_NEAR(s.x, mp_sss_skin[(e * MP_SSS_COSINES + c) * MP_SSS_ALBEDOS + a], 1e-5f);
        }
}

// A channel whose radius is below Cycles' smallest walks as Lambert, as in
// Cycles; NaN and out-of-range inputs stay finite and in the table's range.
TEST(SubsurfaceTest, ZeroRadiusIsLambertAndBadInputStaysFinite) {
  float3 r = mp_subsurface_ratio(MP_SSS_WALK, float3(0.1f), float3(0.0f, 0.1f, 0.0f), 1.0f, 1.0f, 1.4f);
  EXPECT_EQ(r.x, 1.0f);
  EXPECT_LT(r.y, 0.9f);
  EXPECT_EQ(r.z, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float odd[] = {nan, -1.0f, 0.0f, 5.0f, inf, -inf};
  for (float x : odd)
    for (int model : {MP_SSS_WALK, MP_SSS_SKIN}) {
      float3 q[] = {mp_subsurface_ratio(model, float3(x), float3(0.1f), 0.5f, 0.5f, 1.4f),
                    mp_subsurface_ratio(model, float3(0.5f), float3(0.1f), x, 0.5f, 1.4f),
                    mp_subsurface_ratio(model, float3(0.5f), float3(0.1f), 0.5f, x, 1.4f),
                    mp_subsurface_ratio(model, float3(0.5f), float3(0.1f), 0.5f, 0.5f, x)};
      for (const float3& v : q) {
        EXPECT_TRUE(std::isfinite(v.x)) << x;
        EXPECT_GT(v.x, 0.5f) << x;
        EXPECT_LT(v.x, 2.0f) << x;
      }
    }
}

}  // namespace
