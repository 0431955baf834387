/* Sky Texture node, physical models: the sky's radiance for a direction,
 * read from a texture precomputed on the host (native/src/pipeline/
 * sky_nishita.cpp), plus the sun's disc. The conventions are Cycles'
 * (intern/cycles/kernel/svm/sky.h), so the same node gives the same sky:
 *
 * - The texture holds CIE XYZ radiance (D65 white) in rgb. Its columns are
 *   the azimuth relative to the sun, u = 0.5 towards the sun; its rows the
 *   elevation, squeezed towards the horizon: v = sqrt(elevation / (pi/2)).
 *   Linear filtering, extended at the borders.
 * - MP_SKY_HEMISPHERE (Blender 2.90 to 4.5, "Nishita"): rows cover the sky
 *   from the horizon up; below it the horizon row fades to black by
 *   (1 + 2.5 z)^3 and is black under z = -0.4. Inside the sun's disc the
 *   disc replaces the sky.
 * - MP_SKY_SPHERE (Blender 5.0, "Single" and "Multiple Scattering"): rows
 *   cover the whole sphere, v = 0.5 at the horizon; the disc adds to the
 *   sky and is hidden below `earth_angle` (the horizon seen from the
 *   altitude).
 * - The disc's radiance interpolates linearly in elevation between its
 *   lowest and highest points and darkens towards the limb by
 *   1 - 0.6 (1 - sqrt(1 - (angle / radius)^2)).
 *
 * A world baked into a map samples each texel at its centre; a disc smaller
 * than a texel would be missed or counted several times. With `spread`
 * wider than the disc's radius, the disc's light (its integral over the
 * disc, `sun_flux`) is spread over that angle by a smooth kernel of unit
 * integral instead, so the map holds the sun's light wherever the texel
 * centres fall.
 *
 * Compiles as OpenCL C and C++ (include mp_compat.h and mp_types.h first). */
#ifndef MP_TEX_SKY_H
#define MP_TEX_SKY_H

#ifndef __OPENCL_VERSION__
#include <cmath>
using std::isfinite; /* OpenCL's, which mp_tex_image.h uses */
#endif
#include "textures/mp_tex_image.h"

#define MP_SKY_HEMISPHERE 0
#define MP_SKY_SPHERE 1
#define MP_SKY_PI 3.14159265358979f

/* What the lookup needs besides the texture: sky_nishita.cpp computes it
 * from the node's settings. */
typedef struct {
  float3 sun_bottom;   /* XYZ radiance at the disc's lowest point */
  float3 sun_top;      /* ... and at its highest */
  float3 sun_flux;     /* XYZ integral of the disc's radiance (intensity included) */
  float sun_elevation; /* radians, in [-pi/2, pi/2] */
  float sun_rotation;  /* 2 pi minus the node's rotation, in (0, 2 pi] (Cycles' form) */
  float sun_diameter;  /* angular diameter; negative without a disc */
  float sun_intensity;
  float earth_angle;   /* MP_SKY_SPHERE: no disc below this elevation */
  float spread;        /* > disc radius: the disc's light spread over this angle */
  int layout;          /* MP_SKY_HEMISPHERE or MP_SKY_SPHERE */
} MpSky;

/* CIE XYZ (D65) to linear Rec.709, clamped at zero: the inverse of the
 * sRGB primaries' matrix (IEC 61966-2-1), which is what Cycles' xyz_to_rgb
 * holds for Blender's Rec.709 scene-linear space. */
MP_INLINE float3 mp_sky_xyz_to_rgb(float3 c) {
  float r = 3.2404542f * c.x - 1.5371385f * c.y - 0.4985314f * c.z;
  float g = -0.9692660f * c.x + 1.8760108f * c.y + 0.0415560f * c.z;
  float b = 0.0556434f * c.x - 0.2040259f * c.y + 1.0572252f * c.z;
  return MP_F3(fmax(r, 0.0f), fmax(g, 0.0f), fmax(b, 0.0f));
}

/* The angle between unit vectors, accurate when it is small (as the disc's
 * is): 2 atan2(|a - b|, |a + b|). */
MP_INLINE float mp_sky_angle(float3 a, float3 b) {
  return 2.0f * atan2(length(a - b), length(a + b));
}

/* The sun's direction: elevation above the xy plane, azimuth
 * `rotation` (Cycles' form) turning from +Y. */
MP_INLINE float3 mp_sky_sun_direction(float elevation, float rotation) {
  float c = cos(elevation);
  return MP_F3(-c * sin(rotation), c * cos(rotation), sin(elevation));
}

/* The elevation of unit direction d. */
MP_INLINE float mp_sky_elevation(float3 d) { return asin(clamp(d.z, -1.0f, 1.0f)); }

/* The disc's XYZ radiance towards unit direction d, intensity included;
 * zero outside it. */
MP_INLINE float3 mp_sky_sun_xyz(const MpSky* s, float3 d) {
  float3 none = MP_F3(0.0f, 0.0f, 0.0f);
  float half_angle = 0.5f * s->sun_diameter;
  if (!(s->sun_diameter >= 0.0f)) return none;
  float angle = mp_sky_angle(d, mp_sky_sun_direction(s->sun_elevation, s->sun_rotation));
  if (!(angle < half_angle)) return none;
  float elevation = mp_sky_elevation(d);
  float t;
  if (s->layout == MP_SKY_SPHERE) {
    if (!(elevation > s->earth_angle)) return none;
    t = (elevation - s->sun_elevation) / s->sun_diameter + 0.5f;
  } else {
    if (d.z < 0.0f) return none;
    if (s->sun_elevation - half_angle > 0.0f)
      t = (elevation - s->sun_elevation) / s->sun_diameter + 0.5f;
    else if (s->sun_elevation + half_angle > 0.0f)
      /* Partly set: the visible part spans the two stored points. */
      t = elevation / (s->sun_elevation + half_angle);
    else
      return none;
  }
  float r = angle / half_angle;
  float limb = 1.0f - 0.6f * (1.0f - sqrt(fmax(1.0f - r * r, 0.0f)));
  return (s->sun_bottom + t * (s->sun_top - s->sun_bottom)) * (s->sun_intensity * limb);
}

/* The disc's light spread over `spread` around the sun: flux times the
 * kernel 3 / (pi r^2) (1 - (angle / r)^2)^2, of unit integral over the
 * sphere for small r. */
MP_INLINE float3 mp_sky_sun_spread_xyz(const MpSky* s, float3 d) {
  float3 sun = mp_sky_sun_direction(s->sun_elevation, s->sun_rotation);
  float r = s->spread, a = mp_sky_angle(d, sun) / r;
  if (!(a < 1.0f)) return MP_F3(0.0f, 0.0f, 0.0f);
  float k = 1.0f - a * a;
  return s->sun_flux * (3.0f / (MP_SKY_PI * r * r) * k * k);
}

/* The sky's XYZ radiance from the texture towards unit direction d. */
MP_INLINE float3 mp_sky_texture_xyz(const MP_GLOBAL DeviceImage* images, uint image_count,
                                    const MP_GLOBAL float4* texels, int index, const MpSky* s, float3 d) {
  float elevation = mp_sky_elevation(d);
  /* Azimuth measured from +Y towards +X, turned so the sun is at u = 0.5. */
  float u = (atan2(d.x, d.y) + MP_SKY_PI + s->sun_rotation) / (2.0f * MP_SKY_PI);
  u -= floor(u);
  float v, fade = 1.0f;
  if (s->layout == MP_SKY_SPHERE) {
    float e = sqrt(fabs(elevation) / (0.5f * MP_SKY_PI));
    v = 0.5f + 0.5f * (elevation < 0.0f ? -e : e);
  } else if (d.z >= 0.0f) {
    v = sqrt(fmax(elevation, 0.0f) / (0.5f * MP_SKY_PI));
  } else {
    if (d.z < -0.4f) return MP_F3(0.0f, 0.0f, 0.0f);
    fade = 1.0f + 2.5f * d.z;
    fade = fade * fade * fade;
    v = -0.5f; /* the horizon row, extended */
  }
  float4 c = mp_tex_image(images, image_count, texels, index, u, v, MP_IMAGE_LINEAR, MP_EXTENSION_EXTEND);
  return MP_F3(c.x, c.y, c.z) * fade;
}

/* The Sky Texture's colour (linear Rec.709) towards direction `dir` (any
 * length; Cycles' world gives unit directions). */
MP_INLINE float3 mp_tex_sky(const MP_GLOBAL DeviceImage* images, uint image_count, const MP_GLOBAL float4* texels,
                            int index, float3 dir, const MpSky* s) {
  float len = length(dir);
  if (!(len > 0.0f)) return MP_F3(0.0f, 0.0f, 0.0f);
  float3 d = dir / len;
  float3 xyz;
  if (s->sun_diameter >= 0.0f && s->spread > 0.5f * s->sun_diameter) {
    xyz = mp_sky_texture_xyz(images, image_count, texels, index, s, d) + mp_sky_sun_spread_xyz(s, d);
  } else {
    float3 sun = mp_sky_sun_xyz(s, d);
    /* Before 5.0 the disc (above the horizon) takes the sky's place. */
    int replaces = s->layout == MP_SKY_HEMISPHERE && s->sun_diameter >= 0.0f && d.z >= 0.0f &&
                   mp_sky_angle(d, mp_sky_sun_direction(s->sun_elevation, s->sun_rotation)) < 0.5f * s->sun_diameter;
    xyz = replaces ? sun : mp_sky_texture_xyz(images, image_count, texels, index, s, d) + sun;
  }
  return mp_sky_xyz_to_rgb(xyz);
}

#endif
