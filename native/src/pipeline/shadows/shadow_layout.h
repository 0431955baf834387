// How a frame's lights lay out their shadow maps (kernels/shadow/mp_shadow.h):
// each light's space, its maps (a sun's clipmap levels around the camera,
// a local light's cube faces and mips), where each map's page table starts,
// and the view that renders a map. Pure host work, no OpenCL.
#pragma once

#include <cstdint>
#include <vector>

#include "micropoly/scene.h"
#include "core/mp_types.h"
#include "pipeline/frame/frame_params.h"

namespace mp {

// World-space box around everything that can cast or receive shadows,
// displacement included. Empty (lo > hi) for a scene without surfaces.
struct WorldBounds {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  bool empty() const { return !(lo.x <= hi.x); }
};
WorldBounds world_bounds(const Scene& scene);
// One surface's box, displacement and deformation motion included.
WorldBounds surface_bounds(const Scene& scene, const Mesh& mesh);
WorldBounds surface_bounds(const Scene& scene, const BezierPatches& set);
// Each instance's box over the shutter (its motion transforms), displacement
// included: its prototype's surfaces' boxes, found once per prototype,
// carried through the instance's transforms.
std::vector<WorldBounds> instance_bounds(const Scene& scene);

// Levels (or mips) coarser than the pixel footprint asks for, that marking
// falls back to when the shadow memory budget is short; suns keep clipmap
// levels for them.
constexpr int kMaxShadowLevelBias = 4;

// One map of a light: a sun's clipmap level or a cube's face at one mip.
struct ShadowMapInfo {
  int light = 0;        // index in Scene::lights
  int32_t map_id = 0;   // sun: the level's log2 texel size; cube: face * MP_CUBE_MIPS + mip
  uint32_t table = 0;   // first page-table entry
  int side = 0;         // pages per side
  int origin_x = 0, origin_y = 0;  // table slot of the raster's page (0, 0)
  int32_t page_x = 0, page_y = 0;  // absolute position of that page (sun: the window moves with the camera)
  int coarseness = 0;   // larger for coarser maps of the same light (what a short budget keeps first)
  FrameParams view{};   // renders the map (FrameParams.view_kind MP_VIEW_SHADOW)
};

struct ShadowLayout {
  std::vector<DeviceShadow> shadows;        // one per scene light; kind MP_SHADOW_NONE where none
  std::vector<DeviceShadowLevel> levels;    // the suns' clipmap levels
  std::vector<uint64_t> light_keys;         // per scene light: what its pages' contents depend on (0: none)
  std::vector<int> own_bias;                // per scene light: levels coarser than its footprint asks for
  // Per scene light: the lights whose views share a culling pass have the
  // same group (the world's probe suns: many small coarse views, whose
  // passes of their own would cost more in launches than culling saves);
  // every other light is a group of its own.
  std::vector<int> cull_group;
  std::vector<ShadowMapInfo> maps;
  uint32_t table_entries = 0;
  int shadowed_lights = 0;
  // Absolute position of the page in table slot (sx, sy) of map m.
  void page_position(const ShadowMapInfo& m, int sx, int sy, int32_t* x, int32_t* y) const;
};

// The layout for a scene seen by `frame` (the camera's view), for `lights`
// (the scene's and its world's, world_lighting.h). Lights cast
// shadows when the settings and the light allow it and the scene has
// surfaces. `geometry_key` fingerprints what every page's contents depend
// on besides the surfaces it holds (ShadowGeometryKeys::global).
ShadowLayout make_shadow_layout(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame,
                                const WorldBounds& bounds, uint64_t geometry_key);

// Whether the page of `light`'s maps at map `map_id` (ShadowMapInfo) and
// absolute position (x, y) may hold a part of the world-space `box`
// (conservatively: with a margin of two texels).
bool shadow_page_touches(const Light& light, int32_t map_id, int32_t x, int32_t y, const WorldBounds& box);

// Sets every shadowed light's level bias (levels coarser than the
// footprint asks for), in the records the kernels read.
// Every light `bias` levels coarser than its own (a short budget).
void set_shadow_level_bias(ShadowLayout& layout, int bias);
// World probes' own coarsening (world_lighting.h): their shadows are soft.
constexpr int kWorldProbeLevelBias = 2;

}  // namespace mp
