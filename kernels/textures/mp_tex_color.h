/* Colour nodes of Blender's shader nodes, with Cycles' conventions:
 *
 * - Blackbody: Cycles' piecewise fit of the Planckian locus in Rec.709
 *   (a / T + b T + c for red and green, a cubic in T for blue, seven
 *   temperature bands between 800 K and 12000 K, constant outside), taken
 *   to the scene's linear space and clamped at zero.
 * - Wavelength: the CIE 1931 2-degree colour matching functions at 5 nm
 *   steps from 380 nm to 780 nm, interpolated linearly (black outside),
 *   taken from XYZ to the scene's linear space, scaled by 1 / 2.52 and
 *   clamped at zero.
 * - RGB Curves, Vector Curves and Float Curve: Blender's curve mapping
 *   sampled into a table of n entries over [min_x, max_x] (made by the
 *   add-on, as Cycles makes it), read with linear interpolation and, when the
 *   mapping extends by extrapolation, linear extrapolation from the end
 *   entries; the result mixed with the input by Fac.
 * - Bright/Contrast and Gamma.
 *
 * The colour space conversions are 3x3 matrices given as rows, computed by
 * the add-on from Blender's colour management.
 *
 * Compiles as OpenCL C 1.2 and C++17 through mp_compat.h. */
#ifndef MP_TEX_COLOR_H
#define MP_TEX_COLOR_H

#include "core/mp_compat.h"

#ifdef __OPENCL_VERSION__
#define MP_CL_TABLE __constant
#else
#define MP_CL_TABLE static const
#endif

/* ---- tables ------------------------------------------------------------- */

/* Blackbody fit per temperature band: red and green a / T + b T + c,
 * blue ((a T + b) T + c) T + d. */
MP_CL_TABLE float mp_cl_blackbody_r[21] = {
    1.61919106e+03f, -2.05010916e-03f, 5.02995757e+00f, 2.48845471e+03f, -1.11330907e-03f, 3.22621544e+00f,
    3.34143193e+03f, -4.86551192e-04f, 1.76486769e+00f, 4.09461742e+03f, -1.27446582e-04f, 7.25731635e-01f,
    4.67028036e+03f, 2.91258199e-05f,  1.26703442e-01f, 4.59509185e+03f, 2.87495649e-05f,  1.50345020e-01f,
    3.78717450e+03f, 9.35907826e-06f,  3.99075871e-01f};
MP_CL_TABLE float mp_cl_blackbody_g[21] = {
    -4.88999748e+02f, 6.04330754e-04f,  -7.55807526e-02f, -7.55994277e+02f, 3.16730098e-04f,  4.78306139e-01f,
    -1.02363977e+03f, 1.20223470e-04f,  9.36662319e-01f,  -1.26571316e+03f, 4.87340896e-06f,  1.27054498e+00f,
    -1.42529332e+03f, -4.01150431e-05f, 1.43972784e+00f,  -1.17554822e+03f, -2.16378048e-05f, 1.30408023e+00f,
    -5.00799571e+02f, -4.59832026e-06f, 1.09098763e+00f};
MP_CL_TABLE float mp_cl_blackbody_b[28] = {
    5.96945309e-11f,  -4.85742887e-08f, -9.70622247e-05f, -4.07936148e-03f,
    2.40430366e-11f,  5.55021075e-08f,  -1.98503712e-04f, 2.89312858e-02f,
    -1.40949732e-11f, 1.89878968e-07f,  -3.56632824e-04f, 9.10767778e-02f,
    -3.61460868e-11f, 2.84822009e-07f,  -4.93211319e-04f, 1.56723440e-01f,
    -1.97075738e-11f, 1.75359352e-07f,  -2.50542825e-04f, -2.22783266e-02f,
    -1.61997957e-13f, -1.64216008e-08f, 3.86216271e-04f,  -7.38077418e-01f,
    6.72650283e-13f,  -2.73078809e-08f, 4.24098264e-04f,  -7.52335691e-01f};

/* CIE 1931 2-degree colour matching functions (x, y, z) from 380 nm to
 * 780 nm in 5 nm steps. */
MP_CL_TABLE float mp_cl_cie_xyz[243] = {
    0.0014f, 0.0000f, 0.0065f, 0.0022f, 0.0001f, 0.0105f, 0.0042f, 0.0001f, 0.0201f, 0.0076f, 0.0002f, 0.0362f,
    0.0143f, 0.0004f, 0.0679f, 0.0232f, 0.0006f, 0.1102f, 0.0435f, 0.0012f, 0.2074f, 0.0776f, 0.0022f, 0.3713f,
    0.1344f, 0.0040f, 0.6456f, 0.2148f, 0.0073f, 1.0391f, 0.2839f, 0.0116f, 1.3856f, 0.3285f, 0.0168f, 1.6230f,
    0.3483f, 0.0230f, 1.7471f, 0.3481f, 0.0298f, 1.7826f, 0.3362f, 0.0380f, 1.7721f, 0.3187f, 0.0480f, 1.7441f,
    0.2908f, 0.0600f, 1.6692f, 0.2511f, 0.0739f, 1.5281f, 0.1954f, 0.0910f, 1.2876f, 0.1421f, 0.1126f, 1.0419f,
    0.0956f, 0.1390f, 0.8130f, 0.0580f, 0.1693f, 0.6162f, 0.0320f, 0.2080f, 0.4652f, 0.0147f, 0.2586f, 0.3533f,
    0.0049f, 0.3230f, 0.2720f, 0.0024f, 0.4073f, 0.2123f, 0.0093f, 0.5030f, 0.1582f, 0.0291f, 0.6082f, 0.1117f,
    0.0633f, 0.7100f, 0.0782f, 0.1096f, 0.7932f, 0.0573f, 0.1655f, 0.8620f, 0.0422f, 0.2257f, 0.9149f, 0.0298f,
    0.2904f, 0.9540f, 0.0203f, 0.3597f, 0.9803f, 0.0134f, 0.4334f, 0.9950f, 0.0087f, 0.5121f, 1.0000f, 0.0057f,
    0.5945f, 0.9950f, 0.0039f, 0.6784f, 0.9786f, 0.0027f, 0.7621f, 0.9520f, 0.0021f, 0.8425f, 0.9154f, 0.0018f,
    0.9163f, 0.8700f, 0.0017f, 0.9786f, 0.8163f, 0.0014f, 1.0263f, 0.7570f, 0.0011f, 1.0567f, 0.6949f, 0.0010f,
    1.0622f, 0.6310f, 0.0008f, 1.0456f, 0.5668f, 0.0006f, 1.0026f, 0.5030f, 0.0003f, 0.9384f, 0.4412f, 0.0002f,
    0.8544f, 0.3810f, 0.0002f, 0.7514f, 0.3210f, 0.0001f, 0.6424f, 0.2650f, 0.0000f, 0.5419f, 0.2170f, 0.0000f,
    0.4479f, 0.1750f, 0.0000f, 0.3608f, 0.1382f, 0.0000f, 0.2835f, 0.1070f, 0.0000f, 0.2187f, 0.0816f, 0.0000f,
    0.1649f, 0.0610f, 0.0000f, 0.1212f, 0.0446f, 0.0000f, 0.0874f, 0.0320f, 0.0000f, 0.0636f, 0.0232f, 0.0000f,
    0.0468f, 0.0170f, 0.0000f, 0.0329f, 0.0119f, 0.0000f, 0.0227f, 0.0082f, 0.0000f, 0.0158f, 0.0057f, 0.0000f,
    0.0114f, 0.0041f, 0.0000f, 0.0081f, 0.0029f, 0.0000f, 0.0058f, 0.0021f, 0.0000f, 0.0041f, 0.0015f, 0.0000f,
    0.0029f, 0.0010f, 0.0000f, 0.0020f, 0.0007f, 0.0000f, 0.0014f, 0.0005f, 0.0000f, 0.0010f, 0.0004f, 0.0000f,
    0.0007f, 0.0002f, 0.0000f, 0.0005f, 0.0002f, 0.0000f, 0.0003f, 0.0001f, 0.0000f, 0.0002f, 0.0001f, 0.0000f,
    0.0002f, 0.0001f, 0.0000f, 0.0001f, 0.0000f, 0.0000f, 0.0001f, 0.0000f, 0.0000f, 0.0001f, 0.0000f, 0.0000f,
    0.0000f, 0.0000f, 0.0000f};

/* ---- helpers ------------------------------------------------------------ */

/* The matrix of rows r0, r1, r2 times v. */
MP_INLINE float3 mp_cl_mat3(float3 r0, float3 r1, float3 r2, float3 v) {
  return MP_F3(r0.x * v.x + r0.y * v.y + r0.z * v.z, r1.x * v.x + r1.y * v.y + r1.z * v.z,
               r2.x * v.x + r2.y * v.y + r2.z * v.z);
}

MP_INLINE float3 mp_cl_max0(float3 c) { return MP_F3(fmax(c.x, 0.0f), fmax(c.y, 0.0f), fmax(c.z, 0.0f)); }

/* ---- Blackbody ------------------------------------------------------------- */

/* Rec.709 colour of a blackbody at temperature t (Kelvin), unclamped. */
MP_INLINE float3 mp_blackbody_rec709(float t) {
  if (t >= 12000.0f) return MP_F3(0.8262954810464208f, 0.9945080501520986f, 1.566307710274283f);
  if (t < 800.0f) return MP_F3(5.413294490189271f, -0.20319390035873933f, -0.0822535242887164f);
  int i = t >= 6365.0f ? 6
          : t >= 3315.0f ? 5
          : t >= 1902.0f ? 4
          : t >= 1449.0f ? 3
          : t >= 1167.0f ? 2
          : t >= 965.0f  ? 1
                         : 0;
  float t_inv = 1.0f / t;
  int k = 3 * i, m = 4 * i;
  float r = mp_cl_blackbody_r[k] * t_inv + mp_cl_blackbody_r[k + 1] * t + mp_cl_blackbody_r[k + 2];
  float g = mp_cl_blackbody_g[k] * t_inv + mp_cl_blackbody_g[k + 1] * t + mp_cl_blackbody_g[k + 2];
  float b = ((mp_cl_blackbody_b[m] * t + mp_cl_blackbody_b[m + 1]) * t + mp_cl_blackbody_b[m + 2]) * t +
            mp_cl_blackbody_b[m + 3];
  return MP_F3(r, g, b);
}

/* Blackbody node. convert 0: the scene's linear space is Rec.709; else the
 * rows r0-r2 take Rec.709 to it. */
MP_INLINE float3 mp_blackbody(float t, int convert, float3 r0, float3 r1, float3 r2) {
  float3 c = mp_blackbody_rec709(t);
  if (convert) c = mp_cl_mat3(r0, r1, r2, c);
  return mp_cl_max0(c);
}

/* ---- Wavelength ------------------------------------------------------------ */

/* CIE XYZ of monochromatic light of wavelength lambda_nm (zero outside the
 * table; indices truncate towards zero, as Blender's do). */
MP_INLINE float3 mp_wavelength_xyz(float lambda_nm) {
  float ii = (lambda_nm - 380.0f) * (1.0f / 5.0f);
  int i = (int)ii;
  if (i < 0 || i >= 80) return MP_F3(0.0f, 0.0f, 0.0f);
  ii -= (float)i;
  int k = 3 * i;
  float3 a = MP_F3(mp_cl_cie_xyz[k], mp_cl_cie_xyz[k + 1], mp_cl_cie_xyz[k + 2]);
  float3 b = MP_F3(mp_cl_cie_xyz[k + 3], mp_cl_cie_xyz[k + 4], mp_cl_cie_xyz[k + 5]);
  return a + ii * (b - a);
}

/* Wavelength node; rows r0-r2 take XYZ (D65) to the scene's linear space. */
MP_INLINE float3 mp_wavelength(float lambda_nm, float3 r0, float3 r1, float3 r2) {
  float3 c = mp_cl_mat3(r0, r1, r2, mp_wavelength_xyz(lambda_nm));
  c = c * (1.0f / 2.52f);
  return mp_cl_max0(c);
}

/* ---- curves ------------------------------------------------------------------ */

/* The lookups are defined twice, by MP_CURVE_FUNCTIONS: for a table among
 * the material's node values (suffix _p, in global memory, so an edited
 * curve builds no program) and for a table compiled into the program as an
 * array (programs written before curve tables became node values). */
#define MP_CURVE_FUNCTIONS(SUFFIX, SPACE)                                                                      \
  /* Channel `channel` of a table of n entries of `stride` floats, at relative                                 \
   * position f (0: first entry, 1: last). */                                                                  \
  MP_INLINE float mp_curve_lookup##SUFFIX(SPACE const float* table, int stride, int channel, int n, float f,   \
                                          int extrapolate) {                                                   \
    if ((f < 0.0f || f > 1.0f) && extrapolate) {                                                               \
      float t0, dy;                                                                                            \
      if (f < 0.0f) {                                                                                          \
        t0 = table[channel];                                                                                   \
        dy = t0 - table[stride + channel];                                                                     \
        f = -f;                                                                                                \
      }                                                                                                        \
      else {                                                                                                   \
        t0 = table[(n - 1) * stride + channel];                                                                \
        dy = t0 - table[(n - 2) * stride + channel];                                                           \
        f = f - 1.0f;                                                                                          \
      }                                                                                                        \
      return t0 + dy * f * (float)(n - 1);                                                                     \
    }                                                                                                          \
    f = fmin(fmax(f, 0.0f), 1.0f) * (float)(n - 1);                                                            \
    int i = clamp((int)f, 0, n - 1);                                                                           \
    float t = f - (float)i;                                                                                    \
    float a = table[i * stride + channel];                                                                     \
    if (t > 0.0f) a = (1.0f - t) * a + t * table[(i + 1) * stride + channel];                                  \
    return a;                                                                                                  \
  }                                                                                                            \
                                                                                                               \
  /* RGB Curves and Vector Curves: `table` holds n (r, g, b) entries sampled                                   \
   * over [min_x, max_x]. */                                                                                   \
  MP_INLINE float3 mp_curves_rgb##SUFFIX(SPACE const float* table, int n, float min_x, float max_x,            \
                                         int extrapolate, float fac, float3 c) {                               \
    float range = max_x - min_x;                                                                               \
    float rx = (c.x - min_x) / range, ry = (c.y - min_x) / range, rz = (c.z - min_x) / range;                  \
    float3 m = MP_F3(mp_curve_lookup##SUFFIX(table, 3, 0, n, rx, extrapolate),                                 \
                     mp_curve_lookup##SUFFIX(table, 3, 1, n, ry, extrapolate),                                 \
                     mp_curve_lookup##SUFFIX(table, 3, 2, n, rz, extrapolate));                                \
    return (1.0f - fac) * c + fac * m;                                                                         \
  }                                                                                                            \
                                                                                                               \
  /* Float Curve: `table` holds n values sampled over [min_x, max_x]. */                                       \
  MP_INLINE float mp_curve_float##SUFFIX(SPACE const float* table, int n, float min_x, float max_x,            \
                                         int extrapolate, float fac, float v) {                                \
    float rel = (v - min_x) / (max_x - min_x);                                                                 \
    float m = mp_curve_lookup##SUFFIX(table, 1, 0, n, rel, extrapolate);                                       \
    return (1.0f - fac) * v + fac * m;                                                                         \
  }

MP_CURVE_FUNCTIONS(, )
MP_CURVE_FUNCTIONS(_p, MP_GLOBAL)

/* ---- Bright/Contrast and Gamma ------------------------------------------------- */

MP_INLINE float3 mp_bright_contrast(float3 c, float bright, float contrast) {
  float a = 1.0f + contrast;
  float b = bright - contrast * 0.5f;
  return MP_F3(fmax(a * c.x + b, 0.0f), fmax(a * c.y + b, 0.0f), fmax(a * c.z + b, 0.0f));
}

/* Positive components raised to gamma, others kept; gamma 0 gives white. */
MP_INLINE float3 mp_gamma(float3 c, float gamma) {
  if (gamma == 0.0f) return MP_F3(1.0f, 1.0f, 1.0f);
  float x = c.x > 0.0f ? pow(c.x, gamma) : c.x;
  float y = c.y > 0.0f ? pow(c.y, gamma) : c.y;
  float z = c.z > 0.0f ? pow(c.z, gamma) : c.z;
  return MP_F3(x, y, z);
}

#endif
