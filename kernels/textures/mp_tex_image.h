/* Image Texture node: texel lookup with Blender's interpolation and extension
 * modes, following Cycles' conventions: texel centres at (i + 1/2) / width,
 * Linear blends the 4 nearest texels, Cubic weights the 4x4 nearest with the
 * uniform cubic B-spline, Closest takes the texel containing the point.
 * Repeat wraps, Extend clamps to the border texels, Clip reads zero outside
 * the image, Mirror reflects at every border. Compiles as OpenCL C and C++
 * (include mp_compat.h and mp_types.h first). */
#ifndef MP_TEX_IMAGE_H
#define MP_TEX_IMAGE_H

#include "closures/mp_world.h" /* the Environment Texture's projections */

#define MP_IMAGE_LINEAR 0
#define MP_IMAGE_CLOSEST 1
#define MP_IMAGE_CUBIC 2
#define MP_EXTENSION_REPEAT 0
#define MP_EXTENSION_EXTEND 1
#define MP_EXTENSION_CLIP 2
#define MP_EXTENSION_MIRROR 3

/* Texel index i of an axis n texels long under `extension`; -1 when Clip
 * leaves it outside. */
MP_INLINE int mp_image_index(int i, int n, int extension) {
  if (extension == MP_EXTENSION_REPEAT) {
    int m = i % n;
    return m < 0 ? m + n : m;
  }
  if (extension == MP_EXTENSION_MIRROR) {
    int period = 2 * n, m = i % period;
    m = m < 0 ? m + period : m;
    return m < n ? m : period - 1 - m;
  }
  if (extension == MP_EXTENSION_CLIP) return i >= 0 && i < n ? i : -1;
  return i < 0 ? 0 : i >= n ? n - 1 : i;
}

MP_INLINE float4 mp_image_texel(const MP_GLOBAL float4* texels, DeviceImage im, int x, int y, int extension) {
  int ix = mp_image_index(x, (int)im.width, extension), iy = mp_image_index(y, (int)im.height, extension);
  if (ix < 0 || iy < 0) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  return texels[(ulong)im.offset + (ulong)iy * im.width + (ulong)ix];
}

/* Uniform cubic B-spline weights at fraction t for texels -1, 0, 1, 2. */
MP_INLINE void mp_image_bspline(float t, float* w) {
  float t2 = t * t, t3 = t2 * t;
  w[0] = (1.0f / 6.0f) * (-t3 + 3.0f * t2 - 3.0f * t + 1.0f);
  w[1] = (1.0f / 6.0f) * (3.0f * t3 - 6.0f * t2 + 4.0f);
  w[2] = (1.0f / 6.0f) * (-3.0f * t3 + 3.0f * t2 + 3.0f * t + 1.0f);
  w[3] = (1.0f / 6.0f) * t3;
}

/* ---- MIP levels. Level 0 is the image; level l + 1 is max(1, w / 2) x
 * max(1, h / 2) texels of level l's size w x h, down to 1 x 1, stored one
 * after the other from the image's offset. Each texel of a level is the
 * mean, over the area it covers, of what the image shows there, in linear
 * colour, as many samples per pixel would average it:
 * - level 1 averages level 0's Linear lookup (decoded after interpolation,
 *   as for an sRGB image Cycles decodes after it) over each texel's area,
 *   so it holds the mean of the surface an unfiltered lookup
 *   shows, not of its texels: for a noisy 8-bit image the two differ by a
 *   fifth, because decoding is not linear;
 * - each further level is the exact box average of the level above
 *   (fractional weights where a size is odd).
 * Colour is averaged weighted by alpha (the mean of colour times alpha,
 * divided by the mean alpha), so premultiplied colour is the plain mean,
 * as Cycles averages its associated-alpha pixels. */
MP_INLINE uint mp_image_half(uint n) { return n > 1u ? n / 2u : 1u; }

MP_INLINE uint mp_image_levels(uint width, uint height) {
  uint levels = 1u;
  while (width > 1u || height > 1u) width = mp_image_half(width), height = mp_image_half(height), ++levels;
  return levels;
}

/* Texels of every level together: about 4/3 of the image's. */
MP_INLINE ulong mp_image_texel_count(uint width, uint height) {
  ulong n = (ulong)width * height;
  while (width > 1u || height > 1u) {
    width = mp_image_half(width), height = mp_image_half(height);
    n += (ulong)width * height;
  }
  return n;
}

/* Level `level` of `im` as an image of its own (sRGB only at level 0). */
MP_INLINE DeviceImage mp_image_level(DeviceImage im, uint level) {
  for (uint l = 0; l < level && (im.width > 1u || im.height > 1u); ++l) {
    im.offset += im.width * im.height;
    im.width = mp_image_half(im.width), im.height = mp_image_half(im.height);
    im.srgb = 0u;
  }
  return im;
}

/* The sRGB transfer function's inverse (IEC 61966-2-1). */
MP_INLINE float mp_srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : pow((fmax(c, 0.0f) + 0.055f) / 1.055f, 2.4f);
}

/* Adds colour c of weight w to a mean weighted by alpha (premultiplied) and
 * a plain one (where no alpha is left to weigh by). */
MP_INLINE void mp_image_accumulate(float4 c, float w, float4* premultiplied, float4* plain) {
  *plain += w * c;
  *premultiplied += (w * c.w) * MP_F4(c.x, c.y, c.z, 1.0f);
}

MP_INLINE float4 mp_image_mean(float4 premultiplied, float4 plain, float weight) {
  float4 c = premultiplied.w > 0.0f ? premultiplied / premultiplied.w : plain / weight;
  c.w = plain.w / weight;
  return c;
}

/* The sRGB decode for building levels, where it runs for every point of
 * every texel of every image at each upload: above the linear segment, a
 * degree-6 polynomial fitted to ((c + 0.055) / 1.055)^2.4 over [0.04045, 1]
 * (least squares over 20,001 even points), within 1.8e-5 of it, in place of a
 * power that costs PoCL a double-precision log and exp (seven times the
 * level's build time on two cores). Encoded values past 1 (not in 8-bit
 * images) take the power. */
MP_INLINE float mp_srgb_to_linear_single(float c) {
  if (c <= 0.04045f) return c / 12.92f;
  if (c > 1.0f) return MP_POWR((c + 0.055f) / 1.055f, 2.4f);
  return 0.000945259506f +
         c * (0.0324432095f +
              c * (0.516486175f + c * (0.700847646f + c * (-0.409055494f + c * (0.20728501f + c * -0.0489606596f)))));
}

/* Gauss-Legendre points (2 per piece) along [a, a + size) of level 0, cut
 * at the texel centres, where the Linear lookup is linear between them:
 * positions relative to `origin` and weights, at most 8 of them (size <= 3). */
MP_INLINE int mp_image_level_points(float a, float size, float origin, float* at, float* weight) {
  int n = 0;
  float end = a + size;
  while (a < end && n < 8) {
    float b = fmin(floor(a - 0.5f) + 1.5f, end); /* the next texel centre past a */
    float w = 0.5f * (b - a), mid = a + w, d = w * 0.57735027f; /* 1/sqrt(3) of the half-width */
    at[n] = mid - d - origin, weight[n++] = w;
    at[n] = mid + d - origin, weight[n++] = w;
    a = b;
  }
  return n;
}

/* Texel (x, y) of level 1 (`to`), from the image `im` (level 0) as its
 * Linear lookup shows it: the mean over its area of that lookup, decoded
 * after interpolation, by Gauss-Legendre points in each piece of the area
 * between texel centres (where the lookup is bilinear). The area is at most
 * 3 texels wide, so its lookups read a window of 5 x 5 texels (the area
 * and one beyond each side, clamped at the image's border), each once. */
MP_INLINE float4 mp_image_first_level_texel(const MP_GLOBAL float4* texels, DeviceImage im, DeviceImage to, uint x,
                                            uint y) {
  float sx = (float)im.width / (float)to.width, sy = (float)im.height / (float)to.height;
  float x0 = (float)x * sx, y0 = (float)y * sy;
  int wx = (int)floor(x0 - 0.5f), wy = (int)floor(y0 - 0.5f);
  float4 window[5][5];
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      int tx = mp_image_index(wx + i, (int)im.width, MP_EXTENSION_EXTEND);
      int ty = mp_image_index(wy + j, (int)im.height, MP_EXTENSION_EXTEND);
      window[j][i] = texels[(ulong)im.offset + (ulong)ty * im.width + (ulong)tx];
    }
  /* Positions in window texels: 0 at the centre of window[.][0]. */
  float ax[8], wxs[8], ay[8], wys[8];
  int nx = mp_image_level_points(x0, sx, (float)wx + 0.5f, ax, wxs);
  int ny = mp_image_level_points(y0, sy, (float)wy + 0.5f, ay, wys);
  float4 premultiplied = MP_F4(0.0f, 0.0f, 0.0f, 0.0f), plain = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  for (int j = 0; j < ny; ++j) {
    int iy = min((int)ay[j], 3);
    float ty = ay[j] - (float)iy;
    for (int i = 0; i < nx; ++i) {
      int ix = min((int)ax[i], 3);
      float tx = ax[i] - (float)ix;
      float4 c = (1.0f - ty) * ((1.0f - tx) * window[iy][ix] + tx * window[iy][ix + 1]) +
                 ty * ((1.0f - tx) * window[iy + 1][ix] + tx * window[iy + 1][ix + 1]);
      if (im.srgb)
        c = MP_F4(mp_srgb_to_linear_single(c.x), mp_srgb_to_linear_single(c.y), mp_srgb_to_linear_single(c.z), c.w);
      mp_image_accumulate(c, wxs[i] * wys[j], &premultiplied, &plain);
    }
  }
  return mp_image_mean(premultiplied, plain, sx * sy);
}

/* Texel (x, y) of level `to` (half of level `from`, not level 0), from level `from`'s texels. */
MP_INLINE float4 mp_image_reduce_texel(const MP_GLOBAL float4* texels, DeviceImage from, DeviceImage to, uint x,
                                       uint y) {
  float sx = (float)from.width / (float)to.width, sy = (float)from.height / (float)to.height;
  float x0 = (float)x * sx, x1 = x0 + sx, y0 = (float)y * sy, y1 = y0 + sy;
  float4 premultiplied = MP_F4(0.0f, 0.0f, 0.0f, 0.0f), plain = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  for (int j = (int)floor(y0); (float)j < y1 && j < (int)from.height; ++j) {
    float wy = fmin(y1, (float)(j + 1)) - fmax(y0, (float)j);
    for (int i = (int)floor(x0); (float)i < x1 && i < (int)from.width; ++i) {
      float w = wy * (fmin(x1, (float)(i + 1)) - fmax(x0, (float)i));
      if (!(w > 0.0f)) continue;
      mp_image_accumulate(texels[(ulong)from.offset + (ulong)j * from.width + (ulong)i], w, &premultiplied, &plain);
    }
  }
  return mp_image_mean(premultiplied, plain, sx * sy);
}

/* Colour decoded from sRGB after filtering; alpha as it is. */
MP_INLINE float4 mp_srgb_to_linear4(float4 c) {
  return MP_F4(mp_srgb_to_linear(c.x), mp_srgb_to_linear(c.y), mp_srgb_to_linear(c.z), c.w);
}

/* Filtered texel values of one image at (u, v). */
MP_INLINE float4 mp_tex_image_filtered(const MP_GLOBAL float4* texels, DeviceImage im, float u, float v,
                                       int interpolation, int extension) {
  if (!(isfinite(u) && isfinite(v))) return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  /* Keep coordinates where int conversion is defined. */
  u = fmin(fmax(u, -1.0e6f), 1.0e6f);
  v = fmin(fmax(v, -1.0e6f), 1.0e6f);
  float x = u * (float)im.width, y = v * (float)im.height;
  if (interpolation == MP_IMAGE_CLOSEST) {
    if (extension == MP_EXTENSION_CLIP && (u < 0.0f || v < 0.0f || u > 1.0f || v > 1.0f))
      return MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
    return mp_image_texel(texels, im, (int)floor(x), (int)floor(y), extension);
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = floor(x), fy = floor(y);
  int ix = (int)fx, iy = (int)fy;
  float tx = x - fx, ty = y - fy;
  if (interpolation == MP_IMAGE_CUBIC) {
    float wx[4], wy[4];
    mp_image_bspline(tx, wx);
    mp_image_bspline(ty, wy);
    float4 sum = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
    for (int j = 0; j < 4; ++j) {
      float4 row = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
      for (int i = 0; i < 4; ++i) row += wx[i] * mp_image_texel(texels, im, ix - 1 + i, iy - 1 + j, extension);
      sum += wy[j] * row;
    }
    return sum;
  }
  float4 a = mp_image_texel(texels, im, ix, iy, extension), b = mp_image_texel(texels, im, ix + 1, iy, extension);
  float4 c = mp_image_texel(texels, im, ix, iy + 1, extension), d = mp_image_texel(texels, im, ix + 1, iy + 1, extension);
  return (1.0f - ty) * ((1.0f - tx) * a + tx * b) + ty * ((1.0f - tx) * c + tx * d);
}

/* RGBA of image `index` at (u, v), scene-linear; magenta for an image index
 * the scene does not have (Blender's colour for a missing image). */
MP_INLINE float4 mp_tex_image(const MP_GLOBAL DeviceImage* images, uint image_count, const MP_GLOBAL float4* texels,
                              int index, float u, float v, int interpolation, int extension) {
  if (index < 0 || (uint)index >= image_count) return MP_F4(1.0f, 0.0f, 1.0f, 1.0f);
  DeviceImage im = images[index];
  float4 c = mp_tex_image_filtered(texels, im, u, v, interpolation, extension);
  if (im.srgb) c = mp_srgb_to_linear4(c);
  return c;
}

/* ---- Filtering over a shading point's footprint (RenderMan filters every
 * lookup by the grid's derivatives the same way). dx and dy are the change
 * of (u, v) from a shaded point to the next one along each axis of its
 * grid: the texture area one micropolygon covers. That parallelogram, in
 * texels, is taken as the ellipse of the same second moments (the
 * eigenvalues of J J^T, J = [dx dy]). A footprint within a texel reads
 * level 0 with the node's own interpolation, exactly the unfiltered lookup.
 * A wider one is read as probes spaced along the ellipse's long axis (as
 * many as its length over its width, up to MP_IMAGE_MAX_ANISOTROPY), each
 * blending the two MIP levels whose texels bracket the probes' spacing
 * (trilinear), as anisotropic texture hardware does (the probe scheme of
 * McCormack et al., "Feline", 1999). Probes sum colour times alpha and
 * alpha, as the levels were built. */
#define MP_IMAGE_MAX_ANISOTROPY 16

/* Level `level`'s lookup at (u, v), linear, colour times alpha in xyz. */
MP_INLINE float4 mp_image_probe(const MP_GLOBAL float4* texels, DeviceImage im, uint level, float u, float v,
                                int interpolation, int extension) {
  DeviceImage l = mp_image_level(im, level);
  float4 c = mp_tex_image_filtered(texels, l, u, v, level == 0u ? interpolation : MP_IMAGE_LINEAR, extension);
  if (l.srgb) c = mp_srgb_to_linear4(c);
  return MP_F4(c.x * c.w, c.y * c.w, c.z * c.w, c.w);
}

/* RGBA of image `index` over the footprint (dx, dy) at (u, v), scene-linear. */
MP_INLINE float4 mp_tex_image_area(const MP_GLOBAL DeviceImage* images, uint image_count,
                                   const MP_GLOBAL float4* texels, int index, float u, float v, float2 dx, float2 dy,
                                   int interpolation, int extension) {
  if (index < 0 || (uint)index >= image_count) return MP_F4(1.0f, 0.0f, 1.0f, 1.0f);
  DeviceImage im = images[index];
  float w = (float)im.width, h = (float)im.height;
  float ax = dx.x * w, ay = dx.y * h, bx = dy.x * w, by = dy.y * h;
  float a = ax * ax + bx * bx, b = ax * ay + bx * by, c = ay * ay + by * by;
  float half_diff = 0.5f * (a - c), mean = 0.5f * (a + c), root = sqrt(half_diff * half_diff + b * b);
  float major = sqrt(mean + root), minor = sqrt(fmax(mean - root, 0.0f));
  if (interpolation == MP_IMAGE_CLOSEST || !(major > 1.0f) || !isfinite(major) || !(isfinite(u) && isfinite(v)))
    return mp_tex_image(images, image_count, texels, index, u, v, interpolation, extension);
  /* The long axis: the eigenvector of the larger eigenvalue, in texels. */
  float lambda = mean + root;
  float ex = half_diff >= 0.0f ? lambda - c : b, ey = half_diff >= 0.0f ? b : lambda - a;
  float el = sqrt(ex * ex + ey * ey);
  if (el > 0.0f) ex /= el, ey /= el;
  else ex = 1.0f, ey = 0.0f;
  float ratio = major / fmax(minor, 1e-6f);
  int probes = (int)ceil(fmin(ratio, (float)MP_IMAGE_MAX_ANISOTROPY));
  probes = probes < 1 ? 1 : probes;
  float spacing = fmax(major / (float)probes, minor);
  uint levels = mp_image_levels(im.width, im.height);
  float lod = fmin(fmax(log2(spacing), 0.0f), (float)(levels - 1u));
  uint l0 = (uint)lod;
  float t = l0 + 1u < levels ? lod - (float)l0 : 0.0f;
  float4 sum = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  for (int k = 0; k < probes; ++k) {
    float s = major * (((float)k + 0.5f) / (float)probes - 0.5f);
    float pu = u + s * ex / w, pv = v + s * ey / h;
    float4 p = mp_image_probe(texels, im, l0, pu, pv, interpolation, extension);
    if (t > 0.0f) p = (1.0f - t) * p + t * mp_image_probe(texels, im, l0 + 1u, pu, pv, interpolation, extension);
    sum += p;
  }
  sum /= (float)probes;
  /* Back to colour and alpha, as the unfiltered lookup returns them. */
  return sum.w > 1e-6f ? MP_F4(sum.x / sum.w, sum.y / sum.w, sum.z / sum.w, sum.w) : MP_F4(0.0f, 0.0f, 0.0f, sum.w);
}

/* ---- Projections (the node's Sphere, Tube and Box), as Cycles defines them:
 * Sphere and Tube first map the unit box [0, 1]^3 to [-1, 1]^3. */
#define MP_IMAGE_PI 3.14159265358979f

/* A change of Sphere or Tube coordinates between neighbouring points,
 * without the whole turn of longitude where they straddle the seam. */
MP_INLINE float2 mp_image_wrapped_change(float2 d) {
  return MP_F2(d.x - floor(d.x + 0.5f), d.y);
}

/* Longitude around z and latitude from the south pole, each in [0, 1]. */
MP_INLINE float2 mp_image_sphere_uv(float3 co) {
  co = 2.0f * co - MP_F3(1.0f, 1.0f, 1.0f);
  float len = sqrt(co.x * co.x + co.y * co.y + co.z * co.z);
  if (!(len > 0.0f)) return MP_F2(0.0f, 0.0f);
  float u = co.x == 0.0f && co.y == 0.0f ? 0.0f : (1.0f - atan2(co.x, co.y) / MP_IMAGE_PI) * 0.5f;
  return MP_F2(u, 1.0f - acos(clamp(co.z / len, -1.0f, 1.0f)) / MP_IMAGE_PI);
}

/* Longitude around z as for Sphere, height along z. */
MP_INLINE float2 mp_image_tube_uv(float3 co) {
  co = 2.0f * co - MP_F3(1.0f, 1.0f, 1.0f);
  float len = sqrt(co.x * co.x + co.y * co.y);
  if (!(len > 0.0f)) return MP_F2(0.0f, 0.0f);
  return MP_F2((1.0f - atan2(co.x / len, co.y / len) / MP_IMAGE_PI) * 0.5f, (co.z + 1.0f) * 0.5f);
}

/* Box: the image projected along x, y and z and blended by the object-space
 * normal n. |n| normalised to sum 1 places the point in a triangle whose
 * corners are the three projections: near a corner one projection alone,
 * along the sides a blend of two, in the middle of all three, the blend
 * zones widening with `blend` (0: hard seams). Each projection is mirrored
 * on the side of the axis where it would read backwards. */
MP_INLINE float4 mp_tex_image_box_area(const MP_GLOBAL DeviceImage* images, uint image_count,
                                       const MP_GLOBAL float4* texels, int index, float3 co, float3 dx, float3 dy,
                                       float3 n, float blend, int interpolation, int extension) {
  float3 a = MP_F3(fabs(n.x), fabs(n.y), fabs(n.z));
  float sum = a.x + a.y + a.z;
  a = sum > 0.0f ? a / sum : MP_F3(1.0f, 0.0f, 0.0f);
  float limit = 0.5f * (1.0f + blend);
  float3 w = MP_F3(0.0f, 0.0f, 0.0f);
  if (a.x > limit * (a.x + a.y) && a.x > limit * (a.x + a.z)) {
    w.x = 1.0f;
  } else if (a.y > limit * (a.x + a.y) && a.y > limit * (a.y + a.z)) {
    w.y = 1.0f;
  } else if (a.z > limit * (a.x + a.z) && a.z > limit * (a.y + a.z)) {
    w.z = 1.0f;
  } else if (blend > 0.0f) {
    if (a.z < (1.0f - limit) * (a.y + a.x)) {
      w.x = clamp((a.x / (a.x + a.y) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.y = 1.0f - w.x;
    } else if (a.x < (1.0f - limit) * (a.y + a.z)) {
      w.y = clamp((a.y / (a.y + a.z) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.z = 1.0f - w.y;
    } else if (a.y < (1.0f - limit) * (a.x + a.z)) {
      w.x = clamp((a.x / (a.x + a.z) - 0.5f * (1.0f - blend)) / blend, 0.0f, 1.0f);
      w.z = 1.0f - w.x;
    } else {
      w = ((2.0f - limit) * a + MP_F3(limit - 1.0f, limit - 1.0f, limit - 1.0f)) / (2.0f * limit - 1.0f);
    }
  } else {
    w.x = 1.0f;
  }
  float4 c = MP_F4(0.0f, 0.0f, 0.0f, 0.0f);
  /* Each projection's (u, v) and its footprint, mirrored with it. */
  if (w.x > 0.0f) {
    float m = n.x < 0.0f ? -1.0f : 1.0f;
    c += w.x * mp_tex_image_area(images, image_count, texels, index, n.x < 0.0f ? 1.0f - co.y : co.y, co.z,
                                 MP_F2(m * dx.y, dx.z), MP_F2(m * dy.y, dy.z), interpolation, extension);
  }
  if (w.y > 0.0f) {
    float m = n.y > 0.0f ? -1.0f : 1.0f;
    c += w.y * mp_tex_image_area(images, image_count, texels, index, n.y > 0.0f ? 1.0f - co.x : co.x, co.z,
                                 MP_F2(m * dx.x, dx.z), MP_F2(m * dy.x, dy.z), interpolation, extension);
  }
  if (w.z > 0.0f) {
    float m = n.z > 0.0f ? -1.0f : 1.0f;
    c += w.z * mp_tex_image_area(images, image_count, texels, index, n.z > 0.0f ? 1.0f - co.y : co.y, co.x,
                                 MP_F2(m * dx.y, dx.x), MP_F2(m * dy.y, dy.x), interpolation, extension);
  }
  return c;
}

/* Box at a point (no footprint): level 0, as RIB programs written before
 * filtering call it. */
MP_INLINE float4 mp_tex_image_box(const MP_GLOBAL DeviceImage* images, uint image_count, const MP_GLOBAL float4* texels,
                                  int index, float3 co, float3 n, float blend, int interpolation, int extension) {
  float3 zero = MP_F3(0.0f, 0.0f, 0.0f);
  return mp_tex_image_box_area(images, image_count, texels, index, co, zero, zero, n, blend, interpolation, extension);
}

#endif
