// Thin-film interference (kernels/closures/mp_thin_film.h) against the textbook
// wave-optics result: each wavelength's Airy reflectance of the film,
// r = (r12 + r23 e^{i delta}) / (1 + r12 r23 e^{i delta}) per polarisation,
// summed against the CIE colour matching functions (the Wavelength node's
// 5 nm table, kernels/textures/mp_tex_color.h) and taken to linear Rec.709.
// The kernel gets there another way (a Fourier series over path orders from
// a table of the 1 nm CIE functions), so agreement checks the table, the
// phases and the truncation together.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>

#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "closures/mp_shade_closures.h"
#include "principled_fixture.h"
#include "textures/mp_tex_color.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
const double kXyzToRec709[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                   {-0.9692660, 1.8760108, 0.0415560},
                                   {0.0556434, -0.2040259, 1.0572252}};

// Amplitude reflection coefficients (s, p) from index n1 onto n2 at
// incidence cosine ci, and the transmitted cosine.
void amplitudes(double ci, double n1, double n2, double* rs, double* rp, double* ct) {
  const double st2 = (n1 / n2) * (n1 / n2) * (1.0 - ci * ci);
  *ct = std::sqrt(1.0 - st2);
  *rs = (n1 * ci - n2 * *ct) / (n1 * ci + n2 * *ct);
  *rp = (n2 * ci - n1 * *ct) / (n2 * ci + n1 * *ct);
}

// The film's reflectance at one wavelength, unpolarised.
double airy(double lambda, double ci, double d, double nf, double nb) {
  double rs12, rp12, c2, rs23, rp23, c3;
  amplitudes(ci, 1.0, nf, &rs12, &rp12, &c2);
  amplitudes(c2, nf, nb, &rs23, &rp23, &c3);
  const std::complex<double> e = std::polar(1.0, 2.0 * kPi * 2.0 * nf * d * c2 / lambda);
  const auto refl = [&](double a, double b) { return std::norm((a + b * e) / (1.0 + a * b * e)); };
  return 0.5 * (refl(rs12, rs23) + refl(rp12, rp23));
}

// The film's reflectance per Rec.709 channel, each channel's sensitivity
// normalised to an integral of 1 (a grey reflectance stays grey).
float3 spectral_film(double ci, double d, double nf, double nb) {
  double num[3] = {0, 0, 0}, den[3] = {0, 0, 0};
  for (double lambda = 380.0; lambda < 780.0; lambda += 0.25) {
    const float3 xyz = mp_wavelength_xyz(float(lambda));
    const double r = airy(lambda, ci, d, nf, nb);
    for (int c = 0; c < 3; ++c) {
      const double s = kXyzToRec709[c][0] * xyz.x + kXyzToRec709[c][1] * xyz.y + kXyzToRec709[c][2] * xyz.z;
      num[c] += r * s;
      den[c] += s;
    }
  }
  return MP_F3(float(num[0] / den[0]), float(num[1] / den[1]), float(num[2] / den[2]));
}

float3 kernel_film(double ci, double d, double nf, double nb) {
  return MP_F3(mp_film_channel(0, float(ci), float(d), float(nf), float(nb), 0, 0, 0, 0),
               mp_film_channel(1, float(ci), float(d), float(nf), float(nb), 0, 0, 0, 0),
               mp_film_channel(2, float(ci), float(d), float(nf), float(nb), 0, 0, 0, 0));
}

}  // namespace

// Soap-bubble and oil-slick films at several thicknesses and angles: the
// kernel's colour within 0.003 of the spectral sum in every channel, where
// the colours themselves span 0.0 to 0.2 and differ between channels by up
// to 0.1.
TEST(ThinFilm, AiryColoursMatchSpectralIntegration) {
  const double thickness[] = {120.0, 250.0, 380.0, 500.0, 700.0, 1000.0};
  const double films[][2] = {{1.33, 1.5}, {1.5, 1.33}, {2.0, 1.5}};
  const double cosines[] = {1.0, 0.7, 0.35};
  double worst = 0.0, spread = 0.0;
  for (const auto& f : films)
    for (double d : thickness)
      for (double ci : cosines) {
        const float3 ref = spectral_film(ci, d, f[0], f[1]), got = kernel_film(ci, d, f[0], f[1]);
        for (int c = 0; c < 3; ++c) {
          worst = std::max(worst, std::fabs(double(got[c] - ref[c])));
          EXPECT_NEAR(got[c], ref[c], 0.003) << "film " << f[0] << " on " << f[1] << ", " << d << " nm, cos " << ci
                                             << ", channel " << c;
        }
        spread = std::max(spread, double(std::max({ref.x, ref.y, ref.z}) - std::min({ref.x, ref.y, ref.z})));
      }
  std::printf("thin film: worst channel difference %.4f, largest spread between channels %.3f\n", worst, spread);
  EXPECT_GT(spread, 0.05);  // the films are coloured, so the comparison can tell
}

// A film fading to nothing leaves the interface's own Fresnel term.
TEST(ThinFilm, VanishingFilmIsThePlainInterface) {
  for (double ci : {1.0, 0.5, 0.2}) {
    const float plain = mp_fresnel_dielectric(float(ci), 1.5f);
    const float3 got = kernel_film(ci, 0.0, 1.33, 1.5);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], plain, 1e-4) << "cos " << ci;
  }
  // Total internal reflection inside a film of lower IOR over a denser one
  // cannot happen from air; from a film denser than the substrate at grazing
  // angles it does, and then everything reflects.
  EXPECT_FLOAT_EQ(mp_film_channel(1, 0.05f, 300.0f, 2.4f, 1.0f, 0.0f, 0.0f, 0.0f, 0), 1.0f);
}

// The Principled BSDF: with a film, its specular layer carries the film and
// the diffuse base gets what the film does not reflect along the view;
// a film of 0 nm changes nothing.
TEST(ThinFilm, PrincipledSpecularLayerCarriesTheFilm) {
  MpPrincipled p = principled_defaults();
  p.roughness = 0.2f;
  p.nv = p.coat_nv = 0.8f;
  p.thin_film_ior = 1.33f;
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f), one = MP_F3(1.0f, 1.0f, 1.0f);
  MpSurface plain, film;
  mp_surface_init(&plain, n);
  mp_surface_init(&film, n);
  mp_add_principled_v4(&plain, one, &p, n);
  p.thin_film = 500.0f;
  mp_add_principled_v4(&film, one, &p, n);
  ASSERT_EQ(plain.count, 2);
  ASSERT_EQ(film.count, 2);
  EXPECT_EQ(plain.c[0].film, 0.0f);
  EXPECT_EQ(film.c[0].film, 500.0f);
  const float3 f = mp_film_dielectric(0.8f, 500.0f, 1.33f, 1.5f, MP_F3(0.04f, 0.04f, 0.04f));
  const float below = 1.0f - std::max({f.x, f.y, f.z});
  EXPECT_NEAR(film.c[1].weight.x, 0.8f * below, 1e-5f);
  // The lobe's Fresnel term is the film's at the half vector's cosine.
  const float3 fr = mp_closure_fresnel(&film.c[0], 0.8f, 0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fr[c], f[c], 1e-6f);
  // Specular IOR Level 0 and no film: no specular layer; with the film the
  // layer stays (the film itself reflects), as in Cycles.
  p.specular = 0.0f;
  MpSurface level0;
  mp_surface_init(&level0, n);
  mp_add_principled_v4(&level0, one, &p, n);
  EXPECT_EQ(level0.count, 2);
  p.thin_film = 0.0f;
  mp_surface_init(&level0, n);
  mp_add_principled_v4(&level0, one, &p, n);
  EXPECT_EQ(level0.count, 1);
}

// A film over metal: thin films leave the metal's F82 colour, thicker ones
// colour it, and every value stays a reflectance.
TEST(ThinFilm, MetalKeepsItsColourUnderAVanishingFilm) {
  const float3 gold = MP_F3(1.0f, 0.78f, 0.34f), tint = MP_F3(1.0f, 1.0f, 1.0f);
  MpClosure c = mp_closure(MP_CLOSURE_GLOSSY, tint, 0, 0.04f, 0.04f);
  c.fresnel = MP_FRESNEL_F82;
  c.f0 = gold;
  c.f82 = tint;
  for (float ci : {1.0f, 0.6f, 0.3f}) {
    const float3 bare = mp_closure_fresnel(&c, ci, 0), thin = mp_film_metal(ci, 0.0f, 1.5f, gold, tint);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(thin[k], bare[k], 0.02f) << "cos " << ci << " channel " << k;
    const float3 thick = mp_film_metal(ci, 400.0f, 1.5f, gold, tint);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(thick[k], 0.0f);
      EXPECT_LE(thick[k], 1.0f);
    }
    const float3 d = thick - bare;
    EXPECT_GT(std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}), 0.04f) << "cos " << ci;
  }
}

// Film inputs straight from nodes may be anything: a NaN or negative
// thickness is no film, and an IOR of 0, NaN or a huge one, or an infinite
// thickness, still gives reflectances in [0, 1].
TEST(ThinFilm, DegenerateInputsStayReflectances) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float3 n = MP_F3(0.0f, 0.0f, 1.0f), one = MP_F3(1.0f, 1.0f, 1.0f);
  const float cases[][2] = {{nan, 1.33f}, {-50.0f, 1.33f}, {400.0f, 0.0f}, {400.0f, nan}, {400.0f, 1e6f},
                            {inf, 1.33f}, {1e9f, 1.5f}};
  for (const auto& c : cases)
    for (int metal = 0; metal < 2; ++metal) {
      MpPrincipled p = principled_defaults();
      p.metallic = float(metal);
      p.thin_film = c[0];
      p.thin_film_ior = c[1];
      p.film_on_metal = 1;
      MpSurface s;
      mp_surface_init(&s, n);
      mp_add_principled_v4(&s, one, &p, n);
      ASSERT_GE(s.count, 1);
      if (!(c[0] > MP_THIN_FILM_MIN)) EXPECT_EQ(s.c[0].film, 0.0f);
      for (int i = 0; i < s.count; ++i) {
        EXPECT_TRUE(std::isfinite(s.c[i].weight.x)) << c[0] << " " << c[1];
        for (float cos_vh : {1.0f, 0.5f, 0.05f}) {
          const float3 f = mp_closure_fresnel(&s.c[i], cos_vh, 0);
          for (int k = 0; k < 3; ++k) {
            EXPECT_GE(f[k], 0.0f) << c[0] << " " << c[1] << " metal " << metal;
            EXPECT_LE(f[k], 1.0f) << c[0] << " " << c[1] << " metal " << metal;
          }
        }
      }
    }
}
