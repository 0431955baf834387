// The closures' BSDFs (kernels/closures/mp_bsdf.h), the Principled BSDF's layers
// (kernels/closures/mp_principled.h) and closure lighting (kernels/closures/mp_shade_closures.h)
// on the host, against quadrature and textbook identities.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "closures/mp_shade_closures.h"
#include "principled_fixture.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

float3 spherical(double theta, double phi) {
  return MP_F3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

// Integrates f(l) over the hemisphere about +z with a midpoint rule.
template <class F>
double hemisphere(F f, int n = 256) {
  double sum = 0.0;
  const double dt = 0.5 * kPi / n, dp = 2.0 * kPi / (2 * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double t = (i + 0.5) * dt, p = (j + 0.5) * dp;
      sum += f(spherical(t, p)) * std::sin(t) * dt * dp;
    }
  return sum;
}

// The unpolarised dielectric reflectance from Snell's law and the two
// polarisations (Born & Wolf), a different route to mp_fresnel_dielectric's.
double fresnel_reference(double cos_i, double eta) {
  const double sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin_t2 >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t2);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

TEST(Closures, DielectricFresnelMatchesSnellAndBornWolf) {
  for (double eta : {1.1, 1.33, 1.5, 2.4, 1.0 / 1.5})
    for (int k = 1; k <= 100; ++k) {
      const double c = k / 100.0;
      EXPECT_NEAR(mp_fresnel_dielectric(float(c), float(eta)), fresnel_reference(c, eta), 2e-5) << eta << " " << c;
    }
  EXPECT_NEAR(mp_fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(mp_f0_from_ior(mp_ior_from_f0(0.08f)), 0.08f, 1e-6f);
}

// The anisotropic GGX distribution's projected area is one: int D (n.h) dh = 1.
TEST(Closures, GgxDistributionIsNormalised) {
  for (float ax : {0.05f, 0.2f, 0.6f})
    for (float ay : {0.05f, 0.3f, 0.9f}) {
      const double total = hemisphere([&](float3 h) { return double(mp_ggx_d(h, ax, ay)) * h.z; }, 512);
      EXPECT_NEAR(total, 1.0, 0.02) << ax << " " << ay;
    }
}

// GGX with height-correlated Smith shadowing reflects at most what arrives,
// and nearly all of it while the lobe is narrow (white furnace).
TEST(Closures, GgxReflectionConservesEnergy) {
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f), tx = MP_F3(1.0f, 0.0f, 0.0f), ty = MP_F3(0.0f, 1.0f, 0.0f);
  for (float r : {0.2f, 0.5f, 1.0f})
    for (float nv : {0.2f, 0.6f, 1.0f}) {
      const float3 v = MP_F3(std::sqrt(1.0f - nv * nv), 0.0f, nv);
      const float a = r * r;
      const double e = hemisphere([&](float3 l) { return double(mp_ggx_reflect(n, tx, ty, l, v, a, a)) * l.z; }, 512);
      EXPECT_LE(e, 1.01) << r << " " << nv;
      if (r <= 0.2f && nv >= 0.6f) EXPECT_GT(e, 0.95) << r << " " << nv;
      // The albedo table (scripts/tables/ggx_albedo_table.py, integrating over half
      // vectors) agrees with this quadrature of the kernel's lobe.
      const float2 ab = mp_ggx_albedo(r, nv);
      EXPECT_NEAR(e, ab.x + ab.y, 0.02) << r << " " << nv;
    }
}

TEST(Closures, OrenNayarWithoutRoughnessIsLambert) {
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f), v = normalize(MP_F3(0.3f, 0.1f, 0.8f));
  for (int k = 0; k < 50; ++k) {
    const float3 l = spherical(1.5 * k / 50.0, 0.7 * k);
    EXPECT_NEAR(mp_oren_nayar(n, l, v, 0.0f), l.z / kPi, 1e-6);
  }
  // Rough surfaces keep their albedo below one.
  const double e = hemisphere([&](float3 l) { return double(mp_oren_nayar(n, l, v, 1.0f)); });
  EXPECT_LT(e, 1.0);
  EXPECT_GT(e, 0.7);
}

// Oren-Nayar's closed-form directional albedo (Fujii's G) against
// quadrature of the lobe, and EON's multiple scattering (Blender 4.3 and
// later): a white rough surface reflects all it receives at every angle, a
// coloured one what the closed form says.
TEST(Closures, EonOrenNayarConservesEnergy) {
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f);
  for (float sigma : {0.3f, 0.7f, 1.0f})
    for (float nv : {0.05f, 0.3f, 0.7f, 1.0f}) {
      const float3 v = MP_F3(std::sqrt(1.0f - nv * nv), 0.0f, nv);
      const double single = hemisphere([&](float3 l) { return double(mp_oren_nayar(n, l, v, sigma)); }, 384);
      EXPECT_NEAR(single, mp_oren_nayar_albedo(nv, sigma), 2e-3) << sigma << " " << nv;
      EXPECT_LT(single, 1.0) << sigma << " " << nv;  // single scattering alone loses energy
      if (sigma == 1.0f && nv == 1.0f) EXPECT_LT(single, 0.8);
      for (float rho : {1.0f, 0.5f}) {
        const float3 albedo = MP_F3(rho, rho, rho);
        const double ms = hemisphere([&](float3 l) { return double(mp_eon_ms(albedo, sigma, l.z, nv).x) * l.z; }, 384);
        EXPECT_NEAR(ms, mp_eon_ms_albedo(albedo, sigma, nv).x, 2e-3) << sigma << " " << nv;
        // The closure's weight (rho) times both lobes.
        const double total = rho * (single + ms);
        if (rho == 1.0f) EXPECT_NEAR(total, 1.0, 3e-3) << sigma << " " << nv;
        else EXPECT_LT(total, rho) << sigma << " " << nv;
      }
    }
  // The cosine-weighted average of the closed form is EON's Eavg.
  for (float sigma : {0.3f, 1.0f}) {
    double avg = 0.0;
    const int k = 2000;
    for (int i = 0; i < k; ++i) {
      const double c = (i + 0.5) / k;
      avg += 2.0 * c * mp_oren_nayar_albedo(float(c), sigma) / k;
    }
    EXPECT_NEAR(avg, mp_oren_nayar_average(sigma), 1e-3) << sigma;
  }
  // No roughness: no multiple scattering, and nothing undefined at grazing.
  EXPECT_EQ(mp_eon_ms(MP_F3(1.0f, 1.0f, 1.0f), 0.0f, 0.5f, 0.5f).x, 0.0f);
  EXPECT_TRUE(std::isfinite(mp_oren_nayar_albedo(0.0f, 1.0f)));
  EXPECT_NEAR(mp_oren_nayar_albedo(1e-7f, 1.0f), mp_oren_nayar_albedo(2e-6f, 1.0f), 1e-4);
}

// A rough diffuse closure of any input shades to a finite, non-negative
// colour under a sun and ambient light (the world's path); out-of-range
// roughness reads as its clamp, and EON's lobe adds light to Fujii's.
TEST(Closures, EonDegenerateInputsShadeFinite) {
  DeviceLight lights[2] = {};
  lights[0].color[0] = lights[0].color[1] = lights[0].color[2] = 3.0f;
  lights[0].color[3] = float(MP_LIGHT_DISTANT);
  lights[0].direction[0] = -0.6f;
  lights[0].direction[2] = -0.8f;
  lights[1].color[0] = lights[1].color[1] = lights[1].color[2] = 0.5f;
  lights[1].color[3] = float(MP_LIGHT_AMBIENT);
  const float3 p = MP_F3(0.3f, 0.0f, -5.0f), n = MP_F3(0.0f, 0.0f, 1.0f);
  auto shade = [&](float3 color, float roughness, bool eon) {
    MpSurface s;
    mp_surface_init(&s, n);
    if (eon) mp_add_diffuse_eon(&s, color * 0.8f, color, 0, roughness);
    else mp_add_diffuse(&s, color * 0.8f, 0, roughness);
    return mp_shade_closures(p, n, 0, 0, &s, lights, 2, nullptr, nullptr, nullptr);
  };
  const float inf = INFINITY, nan = NAN;
  for (float r : {nan, -1.0f, 0.0f, 1e-9f, 0.5f, 1.0f, 2.0f, inf})
    for (float c : {nan, -1.0f, 0.0f, 0.5f, 2.0f, inf}) {
      const float3 out = shade(MP_F3(c, 0.5f * c, 0.25f), r, true);
      for (float v : {out.x, out.y, out.z}) {
        EXPECT_TRUE(std::isfinite(v)) << r << " " << c;
        EXPECT_GE(v, 0.0f) << r << " " << c;
      }
    }
  const float3 grey = MP_F3(0.7f, 0.7f, 0.7f);
  EXPECT_EQ(shade(grey, 2.0f, true).x, shade(grey, 1.0f, true).x);
  EXPECT_GT(shade(grey, 1.0f, true).x, shade(grey, 1.0f, false).x * 1.02f);
  EXPECT_EQ(shade(grey, 0.0f, true).x, shade(grey, 0.0f, false).x);  // no roughness: Lambert either way
}

// A toon lobe with a hard edge reflects exactly what arrives within its cone.
TEST(Closures, ToonIsNormalisedOverItsCone) {
  for (float size : {0.2f, 0.5f, 0.9f}) {
    const double e = hemisphere([&](float3 l) { return double(mp_toon(l.z, size, 0.0f)); }, 512);
    EXPECT_NEAR(e, 1.0, 0.02) << size;
  }
}

// The microfiber sheen lobe (Cycles' LTC, fitted to lamp-lit renders of it)
// integrated over the hemisphere against its albedo measured another way:
// Cycles 4.5 in a white furnace (scripts/tables/sheen_albedo_cycles.py; rows of view
// cosine 0.02, 0.125 .. 1, columns of roughness 0.05, 0.125 .. 1).
TEST(Closures, MicrofiberSheenLobeIntegratesToCyclesFurnaceAlbedo) {
  const float furnace[81] = {
      0.1247f, 0.4931f, 0.6347f, 0.6588f, 0.6681f, 0.6778f, 0.6930f, 0.7153f, 0.7408f,
      0.0003f, 0.0612f, 0.3151f, 0.4468f, 0.5189f, 0.5678f, 0.6097f, 0.6480f, 0.6850f,
      0.0000f, 0.0023f, 0.1014f, 0.2548f, 0.3677f, 0.4502f, 0.5166f, 0.5723f, 0.6196f,
      0.0000f, 0.0003f, 0.0268f, 0.1286f, 0.2437f, 0.3429f, 0.4268f, 0.4972f, 0.5562f,
      0.0000f, 0.0001f, 0.0074f, 0.0608f, 0.1539f, 0.2535f, 0.3467f, 0.4285f, 0.4988f,
      0.0000f, 0.0000f, 0.0025f, 0.0279f, 0.0944f, 0.1842f, 0.2788f, 0.3689f, 0.4495f,
      0.0000f, 0.0000f, 0.0010f, 0.0131f, 0.0562f, 0.1307f, 0.2225f, 0.3179f, 0.4074f,
      0.0000f, 0.0000f, 0.0005f, 0.0063f, 0.0329f, 0.0914f, 0.1764f, 0.2746f, 0.3724f,
      0.0000f, 0.0000f, 0.0003f, 0.0033f, 0.0186f, 0.0619f, 0.1380f, 0.2370f, 0.3419f,
  };
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f);
  double worst = 0.0;
  for (int i = 1; i < 9; ++i)
    for (int j = 1; j < 9; ++j) {
      const float nv = i / 8.0f, r = j / 8.0f;
      const float3 v = MP_F3(std::sqrt(1.0f - nv * nv), 0.0f, nv);
      const double e = hemisphere([&](float3 l) { return double(mp_microfiber_sheen(n, l, v, r)); });
      worst = std::max(worst, std::fabs(e - furnace[9 * i + j]));
      EXPECT_NEAR(e, furnace[9 * i + j], 0.01) << "nv " << nv << " roughness " << r;
      EXPECT_NEAR(mp_microfiber_sheen_albedo(nv, r), furnace[9 * i + j], 0.01) << "nv " << nv << " roughness " << r;
    }
  std::printf("worst difference to the furnace: %.4f\n", worst);
}

// Blender 4.x's layers: the diffuse base gets what the specular layer does
// not reflect; metal replaces both; alpha moves weight to transparency.
TEST(Closures, PrincipledLayersShareTheWeight) {
  const float3 one = MP_F3(1.0f, 1.0f, 1.0f);
  MpSurface s;
  mp_surface_init(&s, MP_F3(0.0f, 0.0f, 1.0f));
  MpPrincipled p = principled_defaults();
  mp_add_principled(&s, one, &p, MP_F3(0.0f, 0.0f, 1.0f));
  ASSERT_EQ(s.count, 2);
  EXPECT_EQ(s.c[0].kind, MP_CLOSURE_GLOSSY);
  EXPECT_EQ(s.c[1].kind, MP_CLOSURE_DIFFUSE);
  const float below = 1.0f - mp_layer_albedo(MP_F3(0.04f, 0.04f, 0.04f), 0.5f, 1.0f).x;
  EXPECT_NEAR(s.c[1].weight.x, 0.8f * below, 1e-5f);
  EXPECT_GT(below, 0.9f);

  mp_surface_init(&s, MP_F3(0.0f, 0.0f, 1.0f));
  p.metallic = 1.0f;
  mp_add_principled(&s, one, &p, MP_F3(0.0f, 0.0f, 1.0f));
  ASSERT_EQ(s.count, 1);
  EXPECT_EQ(s.c[0].fresnel, MP_FRESNEL_F82);

  mp_surface_init(&s, MP_F3(0.0f, 0.0f, 1.0f));
  p = principled_defaults();
  p.alpha = 0.25f;
  mp_add_principled(&s, one, &p, MP_F3(0.0f, 0.0f, 1.0f));
  EXPECT_NEAR(mp_surface_alpha(&s), 0.25f, 1e-6f);
  EXPECT_NEAR(s.c[0].weight.x, 0.25f, 1e-6f);
}

TEST(Closures, ClosuresPastTheLimitAreCountedAndZeroWeightsCostNothing) {
  MpSurface s;
  mp_surface_init(&s, MP_F3(0.0f, 0.0f, 1.0f));
  mp_add_diffuse(&s, MP_F3(0.0f, 0.0f, 0.0f), 0, 0.0f);
  EXPECT_EQ(s.count, 0);
  for (int i = 0; i < MP_MAX_CLOSURES + 3; ++i) mp_add_diffuse(&s, MP_F3(0.1f, 0.1f, 0.1f), 0, 0.0f);
  EXPECT_EQ(s.count, MP_MAX_CLOSURES);
  EXPECT_EQ(s.dropped, 3);
  // Equal normals share a slot; slots run out into the surface's.
  const float3 a = MP_F3(0.0f, 1.0f, 0.0f), b = MP_F3(1.0f, 0.0f, 0.0f);
  const int sa = mp_surface_normal_slot(&s, a, MP_NORMAL_INPUT_V4);
  EXPECT_EQ(mp_surface_normal_slot(&s, a, MP_NORMAL_INPUT_V4), sa);
  EXPECT_NE(mp_surface_normal_slot(&s, b, MP_NORMAL_INPUT_V4), sa);
}

// One closure of each kind lit by a distant light from the normal: each
// gives its own lobe's response, and a Mix of two is the mix of their colours.
TEST(Closures, ShadingSumsTheClosuresItIsGiven) {
  DeviceLight sun{};
  sun.color[0] = sun.color[1] = sun.color[2] = 3.0f;
  sun.color[3] = float(MP_LIGHT_DISTANT);
  sun.direction[2] = -1.0f;  // travelling down -z: light from +z
  const float3 p = MP_F3(0.0f, 0.0f, -5.0f), n = MP_F3(0.0f, 0.0f, 1.0f);
  auto shade = [&](const MpSurface& s) { return mp_shade_closures(p, n, 0, 0, &s, &sun, 1, nullptr, nullptr, nullptr); };
  MpSurface d;
  mp_surface_init(&d, n);
  mp_add_diffuse(&d, MP_F3(0.5f, 0.5f, 0.5f), 0, 0.0f);
  EXPECT_NEAR(shade(d).x, 3.0 * 0.5 / kPi, 1e-5);
  MpSurface t;
  mp_surface_init(&t, n);
  mp_add_translucent(&t, MP_F3(0.5f, 0.5f, 0.5f), 0);
  EXPECT_NEAR(shade(t).x, 0.0, 1e-6);  // lit from the front only
  MpSurface m;
  mp_surface_init(&m, n);
  mp_add_diffuse(&m, MP_F3(0.5f, 0.5f, 0.5f) * 0.25f, 0, 0.0f);
  mp_add_emission(&m, MP_F3(0.2f, 0.0f, 0.0f) * 0.75f);
  const float3 c = shade(m);
  EXPECT_NEAR(c.x, 0.25 * 3.0 * 0.5 / kPi + 0.15, 1e-5);
  EXPECT_NEAR(c.y, 0.25 * 3.0 * 0.5 / kPi, 1e-5);
}

}  // namespace
