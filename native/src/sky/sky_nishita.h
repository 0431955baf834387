// The Sky Texture node's physical skies, precomputed on the host as Cycles
// does: a texture of the sky's radiance over azimuth and elevation, and the
// sun disc's radiance, both CIE XYZ, read by kernels/textures/mp_tex_sky.h.
//
// Models, by the Blender version that offers them:
// - Nishita (Blender 2.90 to 4.5; "Single Scattering" in 5.0): single
//   scattering of sunlight by air (Rayleigh) and aerosols (Mie) with ozone
//   absorption, integrated over 21 wavelengths along each view ray through
//   a spherical atmosphere (Nishita, Sirai, Tadamura, Nakamae 1993, "Display
//   of the Earth taking into account atmospheric scattering"), with the
//   constants, spectra and texture layout of Blender's sky model
//   (intern/sky). 5.0 keeps the model and extends the texture below the
//   horizon.
// - Multiple Scattering (Blender 5.0): Fernando García Liñán's spectral sky
//   (4 wavelengths, an analytic fit of multiple scattering, ozone and
//   aerosol profiles; https://fgarlin.com/posts/2024-12-06-spectral_sky/),
//   as Blender 5.0 evaluates it.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace mp {

enum class SkyModel {
  Nishita,             // Blender 2.90-4.5: texture 512 x 128 above the horizon
  SingleScattering,    // Blender 5.0: the same model, 512 x 256 over the sphere
  MultipleScattering,  // Blender 5.0: García Liñán's model, 512 x 256 over the sphere
};

// The node's settings, in its units (radians, metres, densities relative to
// Earth's atmosphere).
struct SkyParameters {
  SkyModel model = SkyModel::Nishita;
  bool sun_disc = true;
  float sun_size = 0.009512f;  // angular diameter
  float sun_intensity = 1.0f;
  float sun_elevation = 0.2617994f;
  float sun_rotation = 0.0f;   // clockwise from +Y seen from above
  float altitude = 0.0f;
  float air = 1.0f;
  float dust = 1.0f;           // "Aerosol" in 5.0
  float ozone = 1.0f;
};

// The precomputed texture: height rows of width texels, row 0 first (texture
// v = 0), CIE XYZ radiance in rgb and 1 in alpha.
struct SkyTexture {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;
};

// Cycles' texture size for the model (width, height).
glm::ivec2 sky_texture_size(SkyModel model);

// The texture for these settings.
SkyTexture sky_texture(const SkyParameters& p);

// What the lookup needs besides the texture (kernels/textures/mp_tex_sky.h,
// MpSky, field by field): the sun disc's radiance at its lowest and highest
// points and its light (the disc's integral), CIE XYZ, intensity included
// in the light only; the sun's position in Cycles' form.
struct SkyLookup {
  glm::vec3 sun_bottom{0.0f}, sun_top{0.0f}, sun_flux{0.0f};
  float sun_elevation = 0.0f;
  float sun_rotation = 0.0f;   // 2 pi minus the node's rotation
  float sun_diameter = -1.0f;  // negative without a disc
  float sun_intensity = 1.0f;
  float earth_angle = 0.0f;    // 5.0: no disc below this elevation
  float spread = 0.0f;         // > disc radius: its light spread over this angle
  int layout = 0;              // MP_SKY_HEMISPHERE (0) or MP_SKY_SPHERE (1)
};

// The lookup values for these settings. `spread`: see mp_tex_sky.h (0: the
// exact disc).
SkyLookup sky_lookup_parameters(const SkyParameters& p, float spread = 0.0f);

// The node's colour (linear Rec.709) towards direction d: the lookup the
// kernels run (mp_tex_sky), here on the host, reading `texture`.
glm::vec3 sky_radiance(const SkyTexture& texture, const SkyLookup& lookup, const glm::vec3& d);

}  // namespace mp
