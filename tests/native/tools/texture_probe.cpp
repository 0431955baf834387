// Evaluates the procedural texture headers on the host, one query per line of
// standard input, and prints the outputs with float round-trip precision.
// tests/blender/test_textures.py compares them against Blender's own render.
//
// Query lines (fields separated by blanks; '#' starts a comment line):
//   noise    dims type normalize scale detail roughness lacunarity offset gain distortion version x y z w
//   musgrave dims type scale detail dimension lacunarity offset gain version x y z w
//   wave     wave_type direction profile scale distortion detail detail_scale detail_roughness phase version x y z
//   voronoi  dims feature metric scale detail roughness lacunarity smoothness exponent randomness normalize
//            version x y z w
//   checker  scale c1r c1g c1b c2r c2g c2b version x y z
//   brick    scale mortar_size mortar_smooth bias brick_width row_height offset offset_frequency squash
//            squash_frequency c1r c1g c1b c2r c2g c2b mr mg mb version x y z
//   gradient type version x y z                 (type: mp_tex_pattern.h's MP_GRADIENT_*)
//   magic    depth scale distortion version x y z
//   white_noise dims version x y z w
//   gabor    type scale frequency anisotropy orientation_2d ox oy oz version x y z   (type 0: 2D, 1: 3D)
//   blackbody convert m00 m01 m02 m10 m11 m12 m20 m21 m22 version temperature   (m: Rec.709 -> scene rows)
//   wavelength m00 m01 m02 m10 m11 m12 m20 m21 m22 version lambda                (m: XYZ -> scene rows)
//   table    id n v0 ... v(n-1)              (defines a curve table for the curve queries; answers "0")
//   curves   table min_x max_x extrapolate fac version x y z   (RGB/Vector Curves; table of 3-float entries)
//   float_curve table min_x max_x extrapolate fac version v
//   bright_contrast bright contrast version r g b
//   gamma    gamma version r g b
//   vector_rotate type invert cx cy cz ax ay az angle ex ey ez version x y z   (type: MP_ROTATE_*)
// Output lines:
//   noise: fac r g b   musgrave: fac   wave: fac r g b
//   voronoi: distance r g b px py pz w radius
//   checker, brick, gradient, magic: fac r g b   white_noise: value r g b
//   gabor: value phase intensity   float_curve: value
//   blackbody, wavelength, curves, bright_contrast, gamma, vector_rotate: r g b (x y z)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "textures/mp_tex_color.h"
#include "textures/mp_tex_gabor.h"
#include "textures/mp_tex_noise.h"
#include "textures/mp_tex_pattern.h"
#include "textures/mp_tex_voronoi.h"
#include "textures/mp_tex_wave.h"
#include "textures/mp_vector_rotate.h"

namespace {

bool parse_fields(char* line, std::vector<float>& out, std::string& name) {
  out.clear();
  char* save = nullptr;
  char* tok = strtok_r(line, " \t\r\n", &save);
  if (!tok || tok[0] == '#') return false;
  name = tok;
  while ((tok = strtok_r(nullptr, " \t\r\n", &save))) out.push_back(std::strtof(tok, nullptr));
  return true;
}

void print3(float a, float3 c) { std::printf("%.9g %.9g %.9g %.9g\n", a, c.x, c.y, c.z); }
void print3(float3 c) { std::printf("%.9g %.9g %.9g\n", c.x, c.y, c.z); }
float3 vec(const std::vector<float>& f, size_t i) { return float3(f[i], f[i + 1], f[i + 2]); }

bool need(const std::vector<float>& f, size_t n, const std::string& name, long line_no) {
  if (f.size() == n) return true;
  std::fprintf(stderr, "line %ld: %s needs %zu numbers, got %zu\n", line_no, name.c_str(), n, f.size());
  return false;
}

}  // namespace

int main() {
  std::vector<float> f;
  std::string name;
  std::vector<char> buf(1 << 20);
  std::map<int, std::vector<float>> tables;
  long line_no = 0;
  int status = 0;
  while (std::fgets(buf.data(), (int)buf.size(), stdin)) {
    ++line_no;
    if (!parse_fields(buf.data(), f, name)) continue;
    if (name == "noise") {
      if (!need(f, 15, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float fac;
      float3 color;
      mp_tex_noise(float3(f[11], f[12], f[13]), f[14], (int)f[0], (int)f[1], (int)f[2], f[3], f[4], f[5], f[6], f[7],
                   f[8], f[9], (int)f[10], &fac, &color);
      std::printf("%.9g %.9g %.9g %.9g\n", fac, color.x, color.y, color.z);
    }
    else if (name == "musgrave") {
      if (!need(f, 13, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float fac = mp_tex_musgrave(float3(f[9], f[10], f[11]), f[12], (int)f[0], (int)f[1], f[2], f[3], f[4], f[5],
                                  f[6], f[7], (int)f[8]);
      std::printf("%.9g\n", fac);
    }
    else if (name == "wave") {
      if (!need(f, 13, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float fac;
      float3 color;
      mp_tex_wave(float3(f[10], f[11], f[12]), (int)f[0], (int)f[1], (int)f[2], f[3], f[4], f[5], f[6], f[7], f[8],
                  (int)f[9], &fac, &color);
      std::printf("%.9g %.9g %.9g %.9g\n", fac, color.x, color.y, color.z);
    }
    else if (name == "voronoi") {
      if (!need(f, 16, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float distance, w_out, radius;
      float3 color, position;
      mp_tex_voronoi(float3(f[12], f[13], f[14]), f[15], (int)f[0], (int)f[1], (int)f[2], f[3], f[4], f[5], f[6],
                     f[7], f[8], f[9], (int)f[10], (int)f[11], &distance, &color, &position, &w_out, &radius);
      std::printf("%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", distance, color.x, color.y, color.z, position.x,
                  position.y, position.z, w_out, radius);
    }
    else if (name == "checker") {
      if (!need(f, 11, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float fac = mp_tex_checker(vec(f, 8), f[0]);
      print3(fac, mp_tex_checker_color(fac, vec(f, 1), vec(f, 4)));
    }
    else if (name == "brick") {
      if (!need(f, 23, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float3 color;
      float fac = mp_tex_brick(vec(f, 20), vec(f, 10), vec(f, 13), vec(f, 16), f[0], f[1], f[2], f[3], f[4], f[5],
                               f[6], (int)f[7], f[8], (int)f[9], (int)f[19], &color);
      print3(fac, color);
    }
    else if (name == "gradient") {
      if (!need(f, 5, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float fac = mp_tex_gradient(vec(f, 2), (int)f[0]);
      print3(fac, float3(fac, fac, fac));
    }
    else if (name == "magic") {
      if (!need(f, 7, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float3 color = mp_tex_magic(vec(f, 4), f[1], (int)f[0], f[2]);
      print3(mp_tex_magic_fac(color), color);
    }
    else if (name == "white_noise") {
      if (!need(f, 6, name, line_no)) { status = 1; std::puts("nan"); continue; }
      int dims = (int)f[0];
      print3(mp_tex_white_noise_value(vec(f, 2), f[5], dims), mp_tex_white_noise_color(vec(f, 2), f[5], dims));
    }
    else if (name == "gabor") {
      if (!need(f, 12, name, line_no)) { status = 1; std::puts("nan"); continue; }
      float value, phase, intensity;
      mp_tex_gabor(vec(f, 9), (int)f[0], f[1], f[2], f[3], f[4], vec(f, 5), &value, &phase, &intensity);
      std::printf("%.9g %.9g %.9g\n", value, phase, intensity);
    }
    else if (name == "blackbody") {
      if (!need(f, 12, name, line_no)) { status = 1; std::puts("nan"); continue; }
      print3(mp_blackbody(f[11], (int)f[0], vec(f, 1), vec(f, 4), vec(f, 7)));
    }
    else if (name == "wavelength") {
      if (!need(f, 11, name, line_no)) { status = 1; std::puts("nan"); continue; }
      print3(mp_wavelength(f[10], vec(f, 0), vec(f, 3), vec(f, 6)));
    }
    else if (name == "table") {
      if (f.size() < 2 || f.size() != 2 + (size_t)f[1]) {
        std::fprintf(stderr, "line %ld: table needs id, n and n values\n", line_no);
        status = 1;
        std::puts("nan");
        continue;
      }
      tables[(int)f[0]] = std::vector<float>(f.begin() + 2, f.end());
      std::puts("0");
    }
    else if (name == "curves" || name == "float_curve") {
      bool rgb = name == "curves";
      if (!need(f, rgb ? 9 : 7, name, line_no)) { status = 1; std::puts("nan"); continue; }
      auto it = tables.find((int)f[0]);
      if (it == tables.end()) {
        std::fprintf(stderr, "line %ld: no table %d\n", line_no, (int)f[0]);
        status = 1;
        std::puts("nan");
        continue;
      }
      const std::vector<float>& t = it->second;
      if (rgb) print3(mp_curves_rgb_p(t.data(), (int)(t.size() / 3), f[1], f[2], (int)f[3], f[4], vec(f, 6)));
      else std::printf("%.9g\n", mp_curve_float_p(t.data(), (int)t.size(), f[1], f[2], (int)f[3], f[4], f[6]));
    }
    else if (name == "bright_contrast") {
      if (!need(f, 6, name, line_no)) { status = 1; std::puts("nan"); continue; }
      print3(mp_bright_contrast(vec(f, 3), f[0], f[1]));
    }
    else if (name == "gamma") {
      if (!need(f, 5, name, line_no)) { status = 1; std::puts("nan"); continue; }
      print3(mp_gamma(vec(f, 2), f[0]));
    }
    else if (name == "vector_rotate") {
      if (!need(f, 16, name, line_no)) { status = 1; std::puts("nan"); continue; }
      print3(mp_vector_rotate((int)f[0], (int)f[1], vec(f, 13), vec(f, 2), vec(f, 5), f[8], vec(f, 9)));
    }
    else {
      std::fprintf(stderr, "line %ld: unknown texture '%s'\n", line_no, name.c_str());
      std::puts("nan");
      status = 1;
    }
  }
  return status;
}
