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
// Output lines:
//   noise: fac r g b   musgrave: fac   wave: fac r g b
//   voronoi: distance r g b px py pz w radius
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "textures/mp_tex_noise.h"
#include "textures/mp_tex_voronoi.h"
#include "textures/mp_tex_wave.h"

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

bool need(const std::vector<float>& f, size_t n, const std::string& name, long line_no) {
  if (f.size() == n) return true;
  std::fprintf(stderr, "line %ld: %s needs %zu numbers, got %zu\n", line_no, name.c_str(), n, f.size());
  return false;
}

}  // namespace

int main() {
  std::vector<float> f;
  std::string name;
  std::vector<char> buf(1 << 16);
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
    else {
      std::fprintf(stderr, "line %ld: unknown texture '%s'\n", line_no, name.c_str());
      std::puts("nan");
      status = 1;
    }
  }
  return status;
}
