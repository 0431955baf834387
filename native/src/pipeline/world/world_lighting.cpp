#include "pipeline/world/world_lighting.h"

#include <algorithm>
#include <cmath>

#include "closures/mp_world.h"

namespace mp {
namespace {

constexpr double kPi = 3.14159265358979323846;

float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Solid angle of a texel in row y: the band's area over the columns.
double texel_solid_angle(int width, int height, int y) {
  const double lo = kPi * (double(y) / height - 0.5), hi = kPi * (double(y + 1) / height - 0.5);
  return (std::sin(hi) - std::sin(lo)) * 2.0 * kPi / width;
}

std::array<float, 9> sh_basis(const glm::vec3& d) {
  std::array<float, 9> b;
  mp_sh9_basis(d, b.data());
  return b;
}

// Energy (luminance times solid angle) per texel, summed over rectangles.
struct EnergyTable {
  int w, h;
  std::vector<double> sum;  // (w + 1) x (h + 1), inclusive prefix sums
  explicit EnergyTable(const WorldMap& m) : w(m.width), h(m.height), sum(size_t(w + 1) * size_t(h + 1), 0.0) {
    for (int y = 0; y < h; ++y) {
      const double sa = texel_solid_angle(w, h, y);
      for (int x = 0; x < w; ++x)
        at(x + 1, y + 1) = at(x, y + 1) + at(x + 1, y) - at(x, y) + luminance(m.radiance[size_t(y) * w + x]) * sa;
    }
  }
  double& at(int x, int y) { return sum[size_t(y) * size_t(w + 1) + size_t(x)]; }
  double rect(int x0, int y0, int x1, int y1) { return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0); }
};

struct Rect {
  int x0, y0, x1, y1;
};

}  // namespace

glm::vec3 world_map_direction(int width, int height, float x, float y) {
  return mp_env_equirect_direction((x + 0.5f) / float(width), (y + 0.5f) / float(height));
}

glm::vec2 world_map_uv(const glm::vec3& d) { return mp_env_equirect_uv(d); }

std::array<glm::vec3, 9> world_irradiance_sh(const WorldMap& map) {
  std::array<glm::dvec3, 9> acc{};
  for (int y = 0; y < map.height; ++y) {
    const double sa = texel_solid_angle(map.width, map.height, y);
    for (int x = 0; x < map.width; ++x) {
      const glm::dvec3 l = glm::dvec3(map.radiance[size_t(y) * map.width + x]) * sa;
      const auto b = sh_basis(world_map_direction(map.width, map.height, float(x), float(y)));
      for (int k = 0; k < 9; ++k) acc[size_t(k)] += l * double(b[size_t(k)]);
    }
  }
  // The cosine lobe's convolution: A_0 = pi, A_1 = 2pi/3, A_2 = pi/4; over pi.
  const double band[3] = {1.0, 2.0 / 3.0, 0.25};
  std::array<glm::vec3, 9> out;
  for (int k = 0; k < 9; ++k) out[size_t(k)] = glm::vec3(acc[size_t(k)] * band[k == 0 ? 0 : k < 4 ? 1 : 2]);
  return out;
}

glm::vec3 eval_irradiance_sh(const std::array<glm::vec3, 9>& sh, const glm::vec3& n) {
  const auto b = sh_basis(n);
  glm::vec3 e(0.0f);
  for (int k = 0; k < 9; ++k) e += sh[size_t(k)] * b[size_t(k)];
  return glm::max(e, glm::vec3(0.0f));
}

std::vector<WorldRegion> median_cut(const WorldMap& map, int regions) {
  std::vector<WorldRegion> out;
  if (map.width <= 0 || map.height <= 0 || regions <= 0) return out;
  EnergyTable table(map);
  std::vector<Rect> rects{{0, 0, map.width, map.height}};
  // Split the region of most energy until there are enough: equal light
  // per region as in Debevec's cut, without needing a power of two.
  while (int(rects.size()) < regions) {
    size_t best = rects.size();
    double best_energy = 0.0;
    for (size_t i = 0; i < rects.size(); ++i) {
      const Rect& r = rects[i];
      if (r.x1 - r.x0 < 2 && r.y1 - r.y0 < 2) continue;
      const double e = table.rect(r.x0, r.y0, r.x1, r.y1);
      if (best == rects.size() || e > best_energy) best = i, best_energy = e;
    }
    if (best == rects.size()) break;
    Rect r = rects[best];
    // Along the side that is longer on the sphere (columns shrink by the
    // cosine of the latitude), at the energy median.
    const double mid_lat = kPi * ((r.y0 + r.y1) * 0.5 / map.height - 0.5);
    const double wide = (r.x1 - r.x0) * (2.0 * kPi / map.width) * std::cos(mid_lat);
    const double tall = (r.y1 - r.y0) * (kPi / map.height);
    const bool split_x = (wide >= tall && r.x1 - r.x0 >= 2) || r.y1 - r.y0 < 2;
    const double half = 0.5 * table.rect(r.x0, r.y0, r.x1, r.y1);
    Rect a = r, b = r;
    if (split_x) {
      int cut = r.x0 + 1;
      while (cut < r.x1 - 1 && table.rect(r.x0, r.y0, cut, r.y1) < half) ++cut;
      a.x1 = b.x0 = cut;
    } else {
      int cut = r.y0 + 1;
      while (cut < r.y1 - 1 && table.rect(r.x0, r.y0, r.x1, cut) < half) ++cut;
      a.y1 = b.y0 = cut;
    }
    rects[best] = a;
    rects.push_back(b);
  }
  for (const Rect& r : rects) {
    WorldRegion g;
    glm::dvec3 light(0.0), dir(0.0), flat_dir(0.0);
    double sa_total = 0.0;
    for (int y = r.y0; y < r.y1; ++y) {
      const double sa = texel_solid_angle(map.width, map.height, y);
      for (int x = r.x0; x < r.x1; ++x) {
        const glm::vec3 c = map.radiance[size_t(y) * map.width + x];
        const glm::dvec3 d(world_map_direction(map.width, map.height, float(x), float(y)));
        light += glm::dvec3(c) * sa;
        dir += d * (double(luminance(c)) * sa);
        flat_dir += d * sa;
        sa_total += sa;
      }
    }
    const glm::dvec3 use = glm::length(dir) > 0.0 ? dir : flat_dir;
    g.light = glm::vec3(light);
    g.direction = glm::length(use) > 0.0 ? glm::vec3(glm::normalize(use)) : glm::vec3(0.0f, 0.0f, 1.0f);
    g.solid_angle = float(sa_total);
    out.push_back(g);
  }
  return out;
}

std::vector<Light> world_lights(const WorldMap& map, const World& world, int probes) {
  std::vector<Light> out;
  if (map.width <= 0 || map.height <= 0) return out;
  if (world.cast_shadows && probes > 0) {
    for (const WorldRegion& r : median_cut(map, probes)) {
      if (!(luminance(r.light) > 0.0f)) continue;
      Light l;
      l.type = Light::Type::Distant;
      l.world_probe = true;
      l.color = r.light;
      l.intensity = 1.0f;
      l.direction = -r.direction;  // the way its light travels
      l.cast_shadows = true;
      // The disk of the region's solid angle, Omega = 2pi (1 - cos(half)),
      // as the sun's angle that softens its shadow; at most 90 degrees,
      // past which a shadow map's blur no longer follows the region.
      const double c = std::clamp(1.0 - double(r.solid_angle) / (2.0 * kPi), -1.0, 1.0);
      l.angle = float(std::min(2.0 * std::acos(c), kPi / 2.0));
      out.push_back(l);
    }
  }
  Light env;
  env.type = Light::Type::Environment;
  env.color = glm::vec3(world.diffuse, world.glossy, 0.0f);
  env.cast_shadows = false;
  const auto sh = world_irradiance_sh(map);
  env.irradiance_sh.reserve(27);
  for (const glm::vec3& c : sh) env.irradiance_sh.insert(env.irradiance_sh.end(), {c.x, c.y, c.z});
  out.push_back(env);
  return out;
}

WorldMap given_world_map(const World& world) {
  WorldMap map;
  map.width = world.width, map.height = world.height;
  const size_t texels = size_t(world.width) * size_t(world.height);
  map.radiance.resize(texels);
  for (size_t i = 0; i < texels; ++i)
    map.radiance[i] = glm::max(glm::vec3(world.radiance[4 * i], world.radiance[4 * i + 1], world.radiance[4 * i + 2]),
                               glm::vec3(0.0f));
  return map;
}

std::vector<glm::vec4> world_map_mips(const WorldMap& map) {
  std::vector<glm::vec4> out;
  if (map.width <= 0 || map.height <= 0) return out;
  out.reserve(size_t(map.width) * size_t(map.height) * 4 / 3 + 16);
  for (const glm::vec3& c : map.radiance) out.emplace_back(c, 1.0f);
  // Each level from the one before it, which starts at `above`.
  size_t above = 0;
  for (int w = map.width, h = map.height; w >= 16 && h >= 2; w /= 2, h /= 2) {
    const int hw = w / 2, hh = h / 2;
    auto at = [&](int x, int y) { return out[above + size_t(std::min(y, h - 1)) * size_t(w) + size_t(x % w)]; };
    const size_t start = out.size();
    for (int y = 0; y < hh; ++y)
      for (int x = 0; x < hw; ++x)
        out.push_back(0.25f * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1)));
    above = start;
  }
  return out;
}

std::vector<glm::vec4> world_glossy_maps(const WorldMap& map) {
  std::vector<glm::vec4> out(size_t(mp_world_glossy_offset(MP_WORLD_GLOSSY_LEVELS)), glm::vec4(0.0f));
  if (map.width <= 0 || map.height <= 0) return out;
  const std::vector<glm::vec4> mips = world_map_mips(map);
  for (int k = 0; k < MP_WORLD_GLOSSY_LEVELS; ++k) {
    const int w = mp_world_glossy_width(k), h = w / 2;
    glm::vec4* level = out.data() + mp_world_glossy_offset(k);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        level[size_t(y) * w + x] = glm::vec4(mp_world_glossy_texel(mips.data(), map.width, map.height, k, x, y), 1.0f);
  }
  return out;
}

namespace {

glm::vec3 map_texel(const WorldMap& m, int x, int y) {
  x = ((x % m.width) + m.width) % m.width;  // longitude wraps
  y = std::clamp(y, 0, m.height - 1);
  return m.radiance[size_t(y) * size_t(m.width) + size_t(x)];
}

glm::vec3 map_lookup(const WorldMap& m, const glm::vec3& d) {
  const glm::vec2 uv = world_map_uv(d);
  const float x = uv.x * m.width - 0.5f, y = uv.y * m.height - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - float(x0), fy = y - float(y0);
  return glm::mix(glm::mix(map_texel(m, x0, y0), map_texel(m, x0 + 1, y0), fx),
                  glm::mix(map_texel(m, x0, y0 + 1), map_texel(m, x0 + 1, y0 + 1), fx), fy);
}

}  // namespace

void composite_world_map(const WorldMap& map, const FrameSetup& frame, const Camera& camera, std::vector<float>& rgba) {
  const FrameParams& f = frame.params;
  if (rgba.size() != size_t(f.width) * size_t(f.height) * 4) return;
  const bool empty = map.width <= 0 || map.height <= 0;
  const glm::mat3 to_world = glm::inverse(glm::mat3(camera.world_to_camera));
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      // The raster mapping inverted at the pixel's centre (mp_types.h,
      // FrameParams): a perspective ray through it, or the view axis.
      glm::vec3 d(0.0f, 0.0f, -1.0f);
      if (!f.ortho) d = glm::vec3((x + 0.5f - f.bx) / f.ax, (y + 0.5f - f.by) / f.ay, -1.0f);
      const glm::vec3 c = empty ? glm::vec3(0.0f) : map_lookup(map, to_world * d);
      float* o = &rgba[(size_t(y) * size_t(f.width) + size_t(x)) * 4];
      const float leave = 1.0f - o[3];
      o[0] += leave * c.x, o[1] += leave * c.y, o[2] += leave * c.z, o[3] = 1.0f;
    }
}

}  // namespace mp
