// The world's light as lights the pipeline already has (scene.h, World).
//
// Diffuse and glossy light from the world is its irradiance, kept as nine
// spherical-harmonic coefficients (Ramamoorthi & Hanrahan 2001): exact
// enough for a Lambertian surface (a few percent), and one record for the
// shader to read. What the scene hides of that light comes from a few probe
// directions: a median cut of the map's energy (Debevec 2005, "A median cut
// algorithm for light probe sampling") into regions of equal light, each a
// distant light with the region's direction and a soft shadow as wide as
// the region. A shaded point's world light is its irradiance times the
// probes' visibility there, weighted by how much light each probe's region
// gives that normal (kernels/closures/mp_shading.h).
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "micropoly/scene.h"
#include "pipeline/frame/frame_params.h"

namespace mp {

// An equirectangular radiance map in World's convention, RGB per texel.
struct WorldMap {
  int width = 0, height = 0;
  std::vector<glm::vec3> radiance;
};

// The unit direction of the map's texel centre (x, y), and back.
glm::vec3 world_map_direction(int width, int height, float x, float y);
glm::vec2 world_map_uv(const glm::vec3& d);

// The map's irradiance over pi as 9 coefficients per channel (order l = 0,
// then m = -1, 0, 1 of l = 1, then m = -2..2 of l = 2), world space.
std::array<glm::vec3, 9> world_irradiance_sh(const WorldMap& map);
// E(n) / pi from those coefficients: what kernels/closures/mp_shading.h computes.
glm::vec3 eval_irradiance_sh(const std::array<glm::vec3, 9>& sh, const glm::vec3& n);

// A region of the median cut: its light (integral of radiance over its
// solid angle, RGB), energy-weighted mean direction (towards the world),
// and solid angle.
struct WorldRegion {
  glm::vec3 light{0.0f};
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
  float solid_angle = 0.0f;
};
std::vector<WorldRegion> median_cut(const WorldMap& map, int regions);

// The lights a world gives, to append after the scene's own: `probes`
// probe lights (none when the world casts no shadows), then the
// environment light.
std::vector<Light> world_lights(const WorldMap& map, const World& world, int probes);

// The map and its box-filtered halvings, one after another, as the
// glossy prefilter reads them (kernels/closures/mp_world.h,
// mp_world_mip_count); empty for an empty map.
std::vector<glm::vec4> world_map_mips(const WorldMap& map);

// The world's glossy maps (kernels/closures/mp_world.h, MP_WORLD_GLOSSY_LEVELS)
// on the host, texel by texel through mp_world_glossy_texel: what the
// device's prefilter (scene_buffers.h, prefilter_world_glossy) computes, for
// tests to hold it to.
std::vector<glm::vec4> world_glossy_maps(const WorldMap& map);

// A World's own radiance array as a map.
WorldMap given_world_map(const World& world);

// Lays the world behind every pixel of the frame (its crop), bilinear in
// the map, under the image `rgba` (4 floats a pixel, rows top first) as an
// opaque film shows it: colour plus the world times what alpha leaves,
// alpha 1.
void composite_world_map(const WorldMap& map, const FrameSetup& frame, const Camera& camera, std::vector<float>& rgba);

}  // namespace mp
