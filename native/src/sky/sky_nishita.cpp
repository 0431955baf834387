#include "sky/sky_nishita.h"

#include <algorithm>
#include <cmath>

#include "core/mp_types.h"
#include "textures/mp_tex_sky.h"

namespace mp {
namespace {

constexpr float kPi = 3.14159265358979f;

// ---- Single scattering (Nishita et al. 1993; Blender's constants) ----------

constexpr float kRayleighScale = 8e3f;         // scale height of air (m)
constexpr float kMieScale = 1.2e3f;            // scale height of aerosols (m)
constexpr float kMieScattering = 2e-5f;        // aerosols' scattering at sea level (1/m)
constexpr float kMieExtinction = 1.11f;        // aerosols' extinction over scattering
constexpr float kMieG = 0.76f;                 // aerosols' anisotropy
constexpr float kEarthRadius = 6360e3f;        // m
constexpr float kAtmosphereRadius = 6420e3f;   // m
constexpr int kSteps = 32;                     // segments of a view ray
constexpr int kWavelengths = 21;               // 380 nm to 780 nm, every 20 nm
constexpr float kStepLambda = 20.0f;           // nm

// Solar spectral irradiance above the atmosphere (W m^-2 nm^-1).
constexpr float kSolarIrradiance[kWavelengths] = {
    1.457568f, 1.565963f, 1.651484f, 1.714962f, 1.757980f, 1.782564f, 1.790951f,
    1.785416f, 1.768156f, 1.741221f, 1.706471f, 1.665561f, 1.619934f, 1.570836f,
    1.519323f, 1.466285f, 1.412459f, 1.358450f, 1.304749f, 1.251750f, 1.199760f};
// Rayleigh scattering coefficient of air at sea level (1/m).
constexpr float kRayleigh[kWavelengths] = {
    5.424820e-5f, 4.418550e-5f, 3.635152e-5f, 3.017929e-5f, 2.526320e-5f, 2.130859e-5f, 1.809838e-5f,
    1.547057e-5f, 1.330285e-5f, 1.150185e-5f, 9.995574e-6f, 8.728000e-6f, 7.655137e-6f, 6.742172e-6f,
    5.961341e-6f, 5.290346e-6f, 4.711157e-6f, 4.209105e-6f, 3.772184e-6f, 3.390513e-6f, 3.055915e-6f};
// Ozone absorption coefficient at the layer's peak (1/m).
constexpr float kOzone[kWavelengths] = {
    3.251268e-9f, 5.853954e-9f, 1.977191e-8f, 7.309569e-8f, 2.008456e-7f, 4.038396e-7f, 6.355134e-7f,
    9.670704e-7f, 1.547974e-6f, 2.090386e-6f, 2.461281e-6f, 2.735513e-6f, 2.151259e-6f, 1.590518e-6f,
    1.123562e-6f, 7.352755e-7f, 4.645013e-7f, 3.309608e-7f, 2.251261e-7f, 1.487913e-7f, 1.682862e-7f};
// CIE 1931 2-degree colour matching functions at the same wavelengths.
constexpr float kCmf[kWavelengths][3] = {
    {0.001368f, 0.000039f, 0.006450f}, {0.014310f, 0.000396f, 0.067850f}, {0.134380f, 0.004000f, 0.645600f},
    {0.348280f, 0.023000f, 1.747060f}, {0.290800f, 0.060000f, 1.669200f}, {0.095640f, 0.139020f, 0.812950f},
    {0.004900f, 0.323000f, 0.272000f}, {0.063270f, 0.710000f, 0.078250f}, {0.290400f, 0.954000f, 0.020300f},
    {0.594500f, 0.995000f, 0.003900f}, {0.916300f, 0.870000f, 0.001650f}, {1.062200f, 0.631000f, 0.000800f},
    {0.854450f, 0.381000f, 0.000190f}, {0.447900f, 0.175000f, 0.000020f}, {0.164900f, 0.061000f, 0.000000f},
    {0.046770f, 0.017000f, 0.000000f}, {0.011359f, 0.004102f, 0.000000f}, {0.002899f, 0.001047f, 0.000000f},
    {0.000690f, 0.000249f, 0.000000f}, {0.000166f, 0.000060f, 0.000000f}, {0.000042f, 0.000015f, 0.000000f}};

// Optical depth towards the sun by Gauss-Laguerre quadrature: densities
// fall off about exponentially along the ray, so 8 nodes of the rule for
// the integral of f(x) e^-x (numpy.polynomial.laguerre.laggauss(8)), scaled
// so the last node (22.86) lands at 0.91 of the way out, with e^x folded
// into the weights, integrate the whole ray (Blender's sky model does the same).
constexpr int kQuadrature = 8;
constexpr float kQuadratureNodes[kQuadrature] = {0.006811185f, 0.03614807f, 0.09004347f, 0.1706680f,
                                                 0.2818362f,   0.4303406f,  0.6296271f,  0.9145253f};
constexpr float kQuadratureWeights[kQuadrature] = {0.01750894f, 0.04135477f, 0.06678839f, 0.09507699f,
                                                   0.1283416f,  0.1707430f,  0.2327233f,  0.3562490f};

glm::vec3 geographic_direction(float latitude, float longitude) {
  return {std::cos(latitude) * std::cos(longitude), std::cos(latitude) * std::sin(longitude), std::sin(latitude)};
}

glm::vec3 spectrum_to_xyz(const float* spectrum) {
  glm::vec3 xyz(0.0f);
  for (int i = 0; i < kWavelengths; ++i) xyz += glm::vec3(kCmf[i][0], kCmf[i][1], kCmf[i][2]) * spectrum[i];
  return xyz * kStepLambda;
}

// Relative densities (air, aerosols, ozone) at a height above sea level:
// exponential for the first two, a tent from 10 to 40 km peaking at 25 km
// for ozone.
glm::vec3 densities(float height) {
  return {std::exp(-height / kRayleighScale), std::exp(-height / kMieScale),
          std::max(0.0f, 1.0f - std::fabs(height - 25000.0f) / 15000.0f)};
}

// Distance from `p` inside a sphere of `radius` along unit `d` to its surface.
float exit_distance(const glm::vec3& p, const glm::vec3& d, float radius) {
  float b = glm::dot(p, d), c = glm::dot(p, p) - radius * radius;
  return -b + std::sqrt(std::max(b * b - c, 0.0f));
}

bool ground_blocks(const glm::vec3& p, const glm::vec3& d) {
  if (d.z >= 0.0f) return false;
  float b = glm::dot(p, d), c = glm::dot(p, p) - kEarthRadius * kEarthRadius;
  return b * b - c >= 0.0f;
}

// Optical depths (air, aerosols, ozone; unit densities) from p out of the
// atmosphere along d.
glm::vec3 optical_depth(const glm::vec3& p, const glm::vec3& d) {
  float length = exit_distance(p, d, kAtmosphereRadius);
  glm::vec3 depth(0.0f);
  for (int i = 0; i < kQuadrature; ++i)
    depth += densities(glm::length(p + (kQuadratureNodes[i] * length) * d) - kEarthRadius) * kQuadratureWeights[i];
  return depth * length;
}

float phase_rayleigh(float mu) { return 3.0f / (16.0f * kPi) * (1.0f + mu * mu); }

// Cornette-Shanks phase function of the aerosols.
float phase_mie(float mu) {
  const float g2 = kMieG * kMieG;
  return 3.0f * (1.0f - g2) * (1.0f + mu * mu) /
         (8.0f * kPi * (2.0f + g2) * std::pow(1.0f + g2 - 2.0f * kMieG * mu, 1.5f));
}

// Sunlight scattered once towards the eye at `origin` along unit `view`:
// spectral radiance per wavelength, by the midpoint rule over kSteps
// segments, attenuated both ways (Nishita et al. 1993, eq. 4).
void single_scattering(const glm::vec3& view, const glm::vec3& sun, const glm::vec3& origin,
                       const glm::vec3& scale, float* spectrum) {
  float length = exit_distance(origin, view, kAtmosphereRadius), segment = length / kSteps;
  float mu = glm::dot(view, sun);
  float phase_r = phase_rayleigh(mu), phase_m = phase_mie(mu);
  std::fill(spectrum, spectrum + kWavelengths, 0.0f);
  glm::vec3 depth(0.0f);
  for (int i = 0; i < kSteps; ++i) {
    glm::vec3 p = origin + ((i + 0.5f) * segment) * view;
    glm::vec3 density = scale * densities(glm::length(p) - kEarthRadius);
    depth += segment * density;
    if (ground_blocks(p, sun)) continue;  // in the Earth's shadow
    glm::vec3 total = depth + scale * optical_depth(p, sun);
    float mie_attenuation = std::exp(-total.y * kMieExtinction * kMieScattering);
    float mie_in = density.y * kMieScattering * phase_m;
    for (int w = 0; w < kWavelengths; ++w) {
      float attenuation = mie_attenuation * std::exp(-(total.x * kRayleigh[w] + total.z * kOzone[w]));
      spectrum[w] += attenuation * (density.x * kRayleigh[w] * phase_r + mie_in) * kSolarIrradiance[w] * segment;
    }
  }
}

// The sun's XYZ radiance seen at `elevation` through the atmosphere: the
// irradiance left after extinction by air and aerosols, over the disc's
// solid angle.
glm::vec3 sun_radiance(float elevation, float altitude, float air, float dust, float solid_angle) {
  glm::vec3 depth = optical_depth({0.0f, 0.0f, kEarthRadius + altitude}, geographic_direction(elevation, 0.0f));
  float spectrum[kWavelengths];
  for (int w = 0; w < kWavelengths; ++w)
    spectrum[w] = kSolarIrradiance[w] *
                  std::exp(-(kRayleigh[w] * depth.x * air + kMieExtinction * kMieScattering * depth.y * dust)) /
                  solid_angle;
  return spectrum_to_xyz(spectrum);
}

// One row of the single-scattering texture at `latitude`: half the columns
// computed, from longitude -pi (away from the sun), the other half mirrored
// (the sky is symmetric about the sun's azimuth). As Blender does, column
// x and column width - 1 - x hold the same value.
void scattering_row(glm::vec4* row, int width, float latitude, const glm::vec3& sun, const glm::vec3& origin,
                    const glm::vec3& scale) {
  float spectrum[kWavelengths];
  for (int x = 0; x < width / 2; ++x) {
    float longitude = 2.0f * kPi / width * x - kPi;
    single_scattering(geographic_direction(latitude, longitude), sun, origin, scale, spectrum);
    glm::vec4 c(spectrum_to_xyz(spectrum), 1.0f);
    row[x] = c;
    row[width - 1 - x] = c;
  }
}

SkyTexture single_scattering_texture(const SkyParameters& p) {
  glm::ivec2 size = sky_texture_size(p.model);
  SkyTexture t{size.x, size.y, std::vector<glm::vec4>(size_t(size.x) * size.y, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f))};
  glm::vec3 origin(0.0f, 0.0f, kEarthRadius + std::clamp(p.altitude, 1.0f, 59999.0f));
  glm::vec3 sun = geographic_direction(p.sun_elevation, 0.0f), scale(p.air, p.dust, p.ozone);
  if (p.model == SkyModel::Nishita) {
    // Rows from the horizon up, denser towards it: latitude grows with the
    // row's square, reaching a little past the zenith.
    float half_step = 0.25f * kPi / t.height;
    for (int y = 0; y < t.height; ++y) {
      float f = float(y) / t.height;
      scattering_row(&t.texels[size_t(y) * t.width], t.width, (0.5f * kPi + half_step) * f * f, sun, origin, scale);
    }
    return t;
  }
  // Blender 5.0: the upper half as above (without the half step), the lower
  // half the horizon row faded as the ground was before.
  int half = t.height / 2;
  for (int y = half; y < t.height; ++y) {
    float f = float(y) / half - 1.0f;
    scattering_row(&t.texels[size_t(y) * t.width], t.width, 0.5f * kPi * f * f, sun, origin, scale);
  }
  for (int y = 0; y < half; ++y) {
    float f = float(y) / half - 1.0f, z = std::sin(0.5f * kPi * f * f);
    float fade = z < 0.4f ? std::pow(1.0f - 2.5f * z, 3.0f) : 0.0f;
    for (int x = 0; x < t.width; ++x) {
      glm::vec4 h = t.texels[size_t(half) * t.width + x];
      t.texels[size_t(y) * t.width + x] = glm::vec4(glm::vec3(h) * fade, 1.0f);
    }
  }
  return t;
}

// ---- Multiple scattering (García Liñán; Blender 5.0) --------------------------

namespace ms {

constexpr float kEarthRadius = 6371.0f;  // km
constexpr float kAtmosphereRadius = kEarthRadius + 100.0f;
constexpr int kTransmittanceSteps = 64, kInscatteringSteps = 64;
constexpr int kLutWidth = 256, kLutHeight = 64;  // transmittance over (cos zenith, altitude)
constexpr float kG = 0.8f;                       // aerosols' anisotropy (Henyey-Greenstein)
constexpr float kGroundAlbedo = 0.3f;
// Four wavelengths: 630, 560, 490 and 430 nm.
const glm::vec4 kSunIrradiance(1.679f, 1.828f, 1.986f, 1.307f);
const glm::vec4 kMolecularScattering(6.605e-3f, 1.067e-2f, 1.842e-2f, 3.156e-2f);  // 1/km at sea level
const glm::vec4 kOzoneCrossSection(3.472e-25f, 3.914e-25f, 1.349e-25f, 11.03e-27f);
constexpr float kOzoneMeanDobson = 334.5f;
const glm::vec4 kAerosolAbsorption(2.8722e-24f, 4.6168e-24f, 7.9706e-24f, 1.3578e-23f);
const glm::vec4 kAerosolScattering(1.5908e-22f, 1.7711e-22f, 2.0942e-22f, 2.4033e-22f);
constexpr float kAerosolBaseDensity = 1.3681e20f, kAerosolBackgroundDensity = 2e6f, kAerosolHeightScale = 0.73f;
// The four wavelengths' radiance to CIE XYZ (columns: wavelengths).
const glm::vec3 kToXyz[4] = {{53.386917738564668f, 22.981337506691025f, 0.0f},
                             {43.904844466369358f, 71.347795700053394f, 0.102506867965741f},
                             {1.6137278251608962f, 18.422960591455485f, 31.742921188390806f},
                             {20.762668673810577f, 2.3614213523314369f, 110.48009643252140f}};

glm::vec3 to_xyz(const glm::vec4& l) { return kToXyz[0] * l.x + kToXyz[1] * l.y + kToXyz[2] * l.z + kToXyz[3] * l.w; }

glm::vec4 exp4(const glm::vec4& v) { return {std::exp(v.x), std::exp(v.y), std::exp(v.z), std::exp(v.w)}; }

// The sun in the xz plane at zenith cosine c, towards -x.
glm::vec3 sun_direction(float c) { return {-std::sqrt(std::max(1.0f - c * c, 0.0f)), 0.0f, c}; }

// Distance along unit d from p to the sphere of `radius` (the near side
// from outside, the far side from inside), or -1 when it is missed.
float sphere_distance(const glm::vec3& p, const glm::vec3& d, float radius) {
  float b = glm::dot(p, d), c = glm::dot(p, p) - radius * radius;
  if (c > 0.0f && b > 0.0f) return -1.0f;
  float disc = b * b - c;
  if (disc < 0.0f) return -1.0f;
  return disc >= b * b ? -b + std::sqrt(disc) : -b - std::sqrt(disc);
}

class Atmosphere {
 public:
  Atmosphere(float air, float aerosol, float ozone) : air_(air), aerosol_(aerosol), ozone_(ozone) {}

  // Extinction (1/km) at `altitude` km per wavelength; `molecular` and
  // `aerosol` get the scattering parts of it.
  glm::vec4 extinction(float altitude, glm::vec4* molecular = nullptr, glm::vec4* aerosol = nullptr) const {
    // Aerosols: an exponential layer over a constant background.
    float aerosol_density = (kAerosolBaseDensity * std::exp(-altitude / kAerosolHeightScale) +
                             kAerosolBackgroundDensity) * aerosol_;
    glm::vec4 a_abs = kAerosolAbsorption * aerosol_density, a_sca = kAerosolScattering * aerosol_density;
    // Ozone: a log-normal profile in altitude (peak near 25 km).
    float log_h = std::log(std::max(altitude, 1e-4f));
    float ozone_density = 3.78547397e20f * std::exp(-(log_h - 3.22261f) * (log_h - 3.22261f) * 5.55555555f - log_h);
    glm::vec4 m_abs = kOzoneCrossSection * kOzoneMeanDobson * ozone_density * ozone_;
    glm::vec4 m_sca = kMolecularScattering * std::exp(-0.07771971f * std::pow(altitude, 1.16364243f)) * air_;
    if (molecular) *molecular = m_sca;
    if (aerosol) *aerosol = a_sca;
    return a_abs + a_sca + m_abs + m_sca;
  }

  // Transmittance from `normalized_altitude` (0 ground, 1 top) towards the
  // sun at zenith cosine c, by the midpoint rule.
  glm::vec4 transmittance(float c, float normalized_altitude) const {
    glm::vec3 d = sun_direction(c), p(0.0f, 0.0f, glm::mix(kEarthRadius, kAtmosphereRadius, normalized_altitude));
    float step = sphere_distance(p, d, kAtmosphereRadius) / kTransmittanceSteps;
    glm::vec4 depth(0.0f);
    for (int i = 0; i < kTransmittanceSteps; ++i)
      depth += extinction(std::max(glm::length(p + d * ((i + 0.5f) * step)) - kEarthRadius, 0.0f)) * step;
    return exp4(-depth);
  }

  void build_lut() {
    lut_.resize(size_t(kLutWidth) * kLutHeight);
    for (int y = 0; y < kLutHeight; ++y)
      for (int x = 0; x < kLutWidth; ++x)
        lut_[size_t(y) * kLutWidth + x] =
            transmittance(2.0f * x / float(kLutWidth - 1) - 1.0f, y / float(kLutHeight - 1));
  }

  // The LUT bilinearly (integer parts truncated, as Blender reads it).
  glm::vec4 lut(float c, float normalized_altitude) const {
    float x = (kLutWidth - 1) * std::clamp(c * 0.5f + 0.5f, 0.0f, 1.0f);
    float y = (kLutHeight - 1) * std::clamp(normalized_altitude, 0.0f, 1.0f);
    int x1 = int(x), y1 = int(y), x2 = std::min(x1 + 1, kLutWidth - 1), y2 = std::min(y1 + 1, kLutHeight - 1);
    float fx = x - x1, fy = y - y1;
    auto at = [&](int xx, int yy) { return lut_[size_t(yy) * kLutWidth + xx]; };
    return glm::mix(glm::mix(at(x1, y1), at(x2, y1), fx), glm::mix(at(x1, y2), at(x2, y2), fx), fy);
  }

  // Light scattered more than once, per unit scattering: light the ground
  // reflects (albedo 0.3, seen under the solid angle the planet subtends)
  // plus a fit of what the rest of the atmosphere scatters.
  glm::vec4 multiple(float c, float normalized_altitude, float distance_to_centre) const {
    float s = kEarthRadius / distance_to_centre;
    float omega = 2.0f * kPi * (1.0f - std::sqrt(std::max(1.0f - s * s, 0.0f)));
    glm::vec4 ground_to_sample = lut(1.0f, 0.0f) / lut(1.0f, normalized_altitude);
    glm::vec4 ground = (1.0f / (4.0f * kPi)) * omega * (kGroundAlbedo / kPi) * lut(c, 0.0f) * ground_to_sample * c;
    glm::vec4 rest = 0.02f * glm::vec4(0.217f, 0.347f, 0.594f, 1.0f) / (1.0f + 5.0f * std::exp(-17.92f * c));
    return rest + ground;
  }

  // Radiance scattered towards `origin` along unit `view` over distance t,
  // each step integrated exactly for constant coefficients (Hillaire 2020,
  // "A Scalable and Production Ready Sky and Atmosphere Rendering Technique").
  glm::vec4 inscattering(const glm::vec3& sun, const glm::vec3& origin, const glm::vec3& view, float t) const {
    float c = glm::dot(-view, sun);
    float phase_m = 3.0f / (16.0f * kPi) * (1.0f + c * c);
    float den = 1.0f + kG * kG + 2.0f * kG * c;
    float phase_a = (1.0f - kG * kG) / (4.0f * kPi * den * std::sqrt(den));
    float dt = t / kInscatteringSteps;
    glm::vec4 radiance(0.0f), transmittance(1.0f);
    for (int i = 0; i < kInscatteringSteps; ++i) {
      glm::vec3 p = origin + view * ((i + 0.5f) * dt);
      float r = glm::length(p), altitude = std::max(r - kEarthRadius, 0.0f);
      float h = altitude / (kAtmosphereRadius - kEarthRadius), cos_sun = glm::dot(p / r, sun);
      glm::vec4 m_sca, a_sca;
      glm::vec4 ext = extinction(altitude, &m_sca, &a_sca);
      glm::vec4 to_sun = lut(cos_sun, h), ms = multiple(cos_sun, h, r);
      glm::vec4 source = kSunIrradiance * (m_sca * (phase_m * to_sun + ms) + a_sca * (phase_a * to_sun + ms));
      glm::vec4 step = exp4(-dt * ext);
      radiance += transmittance * (source - source * step) / glm::max(ext, glm::vec4(1e-7f));
      transmittance *= step;
    }
    return radiance;
  }

 private:
  float air_, aerosol_, ozone_;
  std::vector<glm::vec4> lut_;
};

float altitude_km(float metres) { return std::clamp(metres, 1.0f, 99999.0f) / 1000.0f; }

SkyTexture texture(const SkyParameters& p) {
  glm::ivec2 size = sky_texture_size(p.model);
  SkyTexture t{size.x, size.y, std::vector<glm::vec4>(size_t(size.x) * size.y)};
  Atmosphere atmosphere(p.air, p.dust, p.ozone);
  atmosphere.build_lut();
  glm::vec3 sun = sun_direction(std::cos(0.5f * kPi - p.sun_elevation));
  glm::vec3 origin(0.0f, 0.0f, kEarthRadius + altitude_km(p.altitude));
  for (int y = 0; y < t.height; ++y) {
    // Texel centres; elevation squeezed towards the horizon as the lookup expects.
    float l = 2.0f * (y + 0.5f) / t.height - 1.0f, elevation = (l < 0.0f ? -l * l : l * l) * 0.5f * kPi;
    for (int x = 0; x < t.width / 2; ++x) {
      float azimuth = 2.0f * kPi * (x + 0.5f) / t.width;
      glm::vec3 view = geographic_direction(elevation, azimuth);
      float atmosphere_t = sphere_distance(origin, view, kAtmosphereRadius);
      float ground_t = sphere_distance(origin, view, kEarthRadius);
      glm::vec4 c(to_xyz(atmosphere.inscattering(sun, origin, view, ground_t < 0.0f ? atmosphere_t : ground_t)), 1.0f);
      t.texels[size_t(y) * t.width + x] = c;
      t.texels[size_t(y) * t.width + t.width - 1 - x] = c;
    }
  }
  return t;
}

glm::vec3 sun_radiance(const SkyParameters& p, float elevation, float solid_angle) {
  Atmosphere atmosphere(p.air, p.dust, p.ozone);
  float h = altitude_km(p.altitude) / (kAtmosphereRadius - kEarthRadius);
  return to_xyz(kSunIrradiance * atmosphere.transmittance(std::cos(0.5f * kPi - elevation), h) / solid_angle);
}

}  // namespace ms

// The node's sun position wrapped as Cycles does (SkyTextureNode::
// simplify_settings): elevation into [-pi/2, pi/2] (turning the azimuth
// round when it passes a pole), rotation into Cycles' 2 pi - rotation.
void wrap_sun(float& elevation, float& rotation) {
  elevation = std::fmod(elevation, 2.0f * kPi);
  if (std::fabs(elevation) >= kPi) elevation -= std::copysign(2.0f * kPi, elevation);
  if (elevation >= 0.5f * kPi || elevation <= -0.5f * kPi) {
    elevation = std::copysign(kPi, elevation) - elevation;
    rotation += kPi;
  }
  rotation = std::fmod(rotation, 2.0f * kPi);
  if (rotation < 0.0f) rotation += 2.0f * kPi;
  rotation = 2.0f * kPi - rotation;
}

SkyParameters wrapped(SkyParameters p) {
  wrap_sun(p.sun_elevation, p.sun_rotation);
  return p;
}

MpSky device_form(const SkyLookup& l) {
  MpSky s{};
  s.sun_bottom = l.sun_bottom;
  s.sun_top = l.sun_top;
  s.sun_flux = l.sun_flux;
  s.sun_elevation = l.sun_elevation;
  s.sun_rotation = l.sun_rotation;
  s.sun_diameter = l.sun_diameter;
  s.sun_intensity = l.sun_intensity;
  s.earth_angle = l.earth_angle;
  s.spread = l.spread;
  s.layout = l.layout;
  return s;
}

// The disc's light: its radiance integrated over the disc by the midpoint
// rule in polar coordinates around the sun.
glm::vec3 disc_flux(const MpSky& s) {
  const int rings = 256, sectors = 64;
  float half = 0.5f * s.sun_diameter;
  glm::vec3 sun = mp_sky_sun_direction(s.sun_elevation, s.sun_rotation);
  glm::vec3 t1 = glm::normalize(std::fabs(sun.z) < 0.9f ? glm::cross(sun, glm::vec3(0, 0, 1))
                                                          : glm::cross(sun, glm::vec3(1, 0, 0)));
  glm::vec3 t2 = glm::cross(sun, t1), flux(0.0f);
  for (int i = 0; i < rings; ++i) {
    float g = (i + 0.5f) * half / rings, weight = std::sin(g) * (half / rings) * (2.0f * kPi / sectors);
    for (int j = 0; j < sectors; ++j) {
      float phi = (j + 0.5f) * 2.0f * kPi / sectors;
      glm::vec3 d = std::cos(g) * sun + std::sin(g) * (std::cos(phi) * t1 + std::sin(phi) * t2);
      flux += mp_sky_sun_xyz(&s, d) * weight;
    }
  }
  return flux;
}

}  // namespace

glm::ivec2 sky_texture_size(SkyModel model) {
  return model == SkyModel::Nishita ? glm::ivec2(512, 128) : glm::ivec2(512, 256);
}

SkyTexture sky_texture(const SkyParameters& params) {
  SkyParameters p = wrapped(params);
  return p.model == SkyModel::MultipleScattering ? ms::texture(p) : single_scattering_texture(p);
}

SkyLookup sky_lookup_parameters(const SkyParameters& params, float spread) {
  SkyParameters p = wrapped(params);
  SkyLookup s;
  s.layout = p.model == SkyModel::Nishita ? MP_SKY_HEMISPHERE : MP_SKY_SPHERE;
  s.sun_elevation = p.sun_elevation;
  s.sun_rotation = p.sun_rotation;
  float diameter = std::max(p.sun_size, 0.0005f);  // Cycles' floor, for precision
  s.sun_diameter = p.sun_disc ? diameter : -1.0f;
  s.sun_intensity = p.sun_intensity;
  s.spread = spread;
  // The horizon seen from the altitude (5.0; before, the disc stops at z = 0).
  s.earth_angle = p.model == SkyModel::Nishita
                      ? 0.0f
                      : -(0.5f * kPi - std::asin(ms::kEarthRadius / (ms::kEarthRadius + p.altitude / 1000.0f)));
  float half = 0.5f * diameter, solid_angle = 2.0f * kPi * (1.0f - std::cos(half));
  float bottom = p.sun_elevation - half, top = p.sun_elevation + half;
  if (p.model == SkyModel::MultipleScattering) {
    s.sun_bottom = ms::sun_radiance(p, bottom, solid_angle);
    s.sun_top = ms::sun_radiance(p, top, solid_angle);
  } else if (p.model == SkyModel::Nishita || top > 0.0f) {
    // Below the horizon the disc takes the horizon's colour.
    float altitude = std::clamp(p.altitude, 1.0f, 59999.0f);
    s.sun_bottom = sun_radiance(std::max(bottom, 0.0f), altitude, p.air, p.dust, solid_angle);
    s.sun_top = sun_radiance(std::max(top, 0.0f), altitude, p.air, p.dust, solid_angle);
  }
  s.sun_flux = p.sun_disc ? disc_flux(device_form(s)) : glm::vec3(0.0f);
  return s;
}

glm::vec3 sky_radiance(const SkyTexture& texture, const SkyLookup& lookup, const glm::vec3& d) {
  DeviceImage image{0u, uint(texture.width), uint(texture.height), 0u};
  MpSky s = device_form(lookup);
  return mp_tex_sky(&image, 1u, texture.texels.data(), 0, d, &s);
}

}  // namespace mp
