// What a render gives back: the images (RenderResult) and what it cost
// (RenderStats), apart from the renderer that makes them, so image writers
// and bindings need not see the pipeline.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace mp {

// Device time per stage (OpenCL profiling) except `upload` (host patch
// building and transfer), `readback` (wall time from the read-back's start,
// once every bucket is resolved, until the image is in the result),
// `readback_wait` (how long the caller's thread waited for it, the worker's
// exit and the transfer queue's last finish included: about all of it with
// Renderer::render; with render_overlapped only what was left when the
// caller asked for the pixels), `total` (wall time of the render call) and
// `interval` (set by a caller that renders frames in a loop, as the CLI's
// --repeat does: wall time from this frame's start to the next's).
// shadow_mark: marking the shadow pages the camera needs; shadow: rendering
// the lights' views, the sum of its bound & split, dicing (with displacement
// and alpha) and sampling; shadows_wall: wall time of marking and rendering
// with the host's page allocation between them.
struct StageTimings {
  double upload = 0, bound_split = 0, dice = 0, shade = 0, sample = 0, resolve = 0, readback = 0, total = 0;
  double shadow_mark = 0, shadow = 0, shadow_bound_split = 0, shadow_dice = 0, shadow_sample = 0, shadows_wall = 0;
  double occlusion = 0;  // building the occlusion pyramid (and counting covered pixels)
  double readback_wait = 0, interval = 0;
};

// Shadow maps of one light (kernels/shadow/mp_shadow.h).
struct ShadowLightStats {
  int light = 0;          // index in Scene::lights
  size_t pages = 0;       // pages its receivers use this frame
  size_t bytes = 0;       // their memory plus the light's page table
};

// The frame's shadow maps: pages are 128 x 128 texels of 4 bytes.
struct ShadowStats {
  int lights = 0;                 // lights with shadow maps
  int level_bias = 0;             // maps coarser than the pixels ask for, to keep to the budget
  size_t views = 0;               // maps (levels, faces at a mip) rendered this frame
  size_t pages_requested = 0;     // pages the camera's receivers need
  size_t pages_rendered = 0;      // of which rendered this frame (the others were kept)
  size_t pages_missing = 0;       // left out for want of memory
  size_t micropolygons = 0;       // diced for the lights' views
  size_t subpatches_occluded = 0; // sub-patches of the lights' views culled as hidden behind what the pages hold
  size_t marking_passes = 0;      // markings that diced the view again: its vertices passed their share of the budget
  size_t marking_occluded = 0;    // sub-patches of the markings' coarse camera view culled as hidden by its depth
  size_t budget_bytes = 0;        // RenderSettings::shadow_memory_mib
  size_t peak_bytes = 0;          // shadow map device memory held: pages, page tables, requests, masks, views
  size_t batches = 0;             // dice batches of the markings and the lights' views
  double mark_wall_ms = 0;        // wall time of the markings, requests read back included
  double render_wall_ms = 0;      // wall time of allocating, writing the page tables and rendering pages
  std::vector<ShadowLightStats> per_light;
};

struct RenderStats {
  std::string device;
  std::string resolver;  // the resolve's kernel: "tiles" or "pixels" (RenderSettings::resolver)
  std::string sampler;   // the camera's sampler: "tiles", "bins" or "micropolygons" (RenderSettings::sampler)
  int width = 0, height = 0, spp = 0;
  size_t patches = 0;        // roots of one view: patches placed on their own and every instance's
  size_t instances = 0;      // instances' placed surfaces (scene.h Instance)
  size_t scene_bytes = 0;    // device memory of the scene's patches, objects and instances
  size_t subpatches_diced = 0;
  size_t micropolygons = 0;
  // Dicing density: micropolygons that reached the rasteriser and their total
  // screen area; micropolygons_sampled / sampled_area_px is micropolygons per
  // pixel of surface, i.e. per covered pixel per depth layer.
  size_t micropolygons_sampled = 0;
  double sampled_area_px = 0;
  // Samples the rasteriser tested against micropolygon edges (depth pass):
  // per sample of the frame, the stochastic rasteriser's cost of blur.
  size_t sample_tests = 0;
  // Occlusion culling (RenderSettings::occlusion_culling): sub-patches bound
  // & split dropped as hidden behind what was already sampled; pixels with a
  // surface in any sample. sampled_area_px / covered_pixels is the depth
  // complexity (surface layers rasterised per covered pixel).
  size_t subpatches_occluded = 0;
  size_t covered_pixels = 0;
  // The camera's roots: how many of their boxes cover a point of the frame
  // on average (an estimate from above of its depth complexity), whether
  // they were taken in waves (OcclusionWaves) and in how many.
  double root_overlap = 0;
  bool occlusion_waves = false;
  size_t waves = 0;
  // Visibility first (RenderSettings::visibility_first): diced sub-patches
  // whose opaque grids owned no sample before shading, left unshaded.
  size_t subpatches_unshaded = 0;
  size_t bound_split_peak_bytes = 0;
  // The pool material programs hand their closures to lighting in
  // (mp_surface_record.h): bytes held, within 32 MiB on CPUs, 256 on GPUs.
  size_t surface_record_bytes = 0;
  size_t batches = 0;
  size_t bound_split_launches = 0;
  // Times the host waited for the device during the frame (a finish, a
  // blocking read, write or map, an event), and how many in each phase
  // ("shadows/bound_split", ...; most first): each is a round trip in which
  // a GPU runs dry; and the kernels launched, in all and per phase
  // (native/src/cl/queue_counts.h).
  size_t host_waits = 0;
  std::vector<std::pair<std::string, size_t>> host_waits_by_phase;
  size_t kernel_launches = 0;
  std::vector<std::pair<std::string, size_t>> kernel_launches_by_phase;
  // Buckets the frame was rendered in (RenderSettings::sample_memory_mib).
  size_t buckets = 1;
  double program_build_ms = 0;       // includes loads from the program cache (program_cache_hit)
  bool program_cache_hit = false;
  bool cancelled = false;
  // The scene's device buffers were those of the previous render (same
  // geometry, camera placement, materials, lights and images).
  bool scene_reused = false;
  ShadowStats shadows;
  StageTimings timings_ms;
  std::string to_json() const;
};

// Pixels are stored top row first. rgba: 4 floats per pixel, premultiplied,
// scene-linear; where the camera sees the scene's world (World::camera, an
// opaque film) it lies behind the objects already and alpha is 1. depth:
// camera-space depth (1e10 where empty); normal: 3 floats per pixel, world
// space. depth and normal are empty when the settings turn those passes off
// (normal also without RenderSettings::normal_pass).
struct RenderResult {
  int width = 0, height = 0;
  std::vector<float> rgba, depth, normal;
  RenderStats stats;
};

}  // namespace mp
