// Material programs: each distinct node tree's OpenCL C, built into its own
// program (kernels/materials/material_program.cl) and kept across frames,
// so an unchanged tree is never rebuilt and a changed one rebuilds alone
// (from the program cache when it was built before: program_cache.h).
#pragma once

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "cl/device_session.h"
#include "micropoly/renderer.h"
#include "micropoly/scene.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/pass/stage_timer.h"
#include "pipeline/world/world_lighting.h"

namespace mp {

class MaterialPrograms {
 public:
  explicit MaterialPrograms(DeviceSession& session)
      : session_(session), normals_(session.program(), "displaced_normals") {}
  // Builds what the scene's materials use; adds the build time to `stats`.
  void prepare(const Scene& scene, RenderStats& stats);
  // Displacement of every program that displaces, then (unless a pass
  // needs positions only) the normals of the displaced grids from their new
  // vertices.
  void displace(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                GridBuffers& grids, StageTimer& timer, bool normals = true);
  // Shades the vertices whose materials compute their Principled inputs
  // (with `visible`, not those of opaque grids it leaves unmarked:
  // ShadeStage::run).
  void shade(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
             GridBuffers& grids, const ShadowInputs& shadows, const cl::Buffer& visible, StageTimer& timer);
  // The world program's radiance map (scene.h, World), baked on the device
  // with the scene's images; empty when the world has no program.
  WorldMap bake_world(const Scene& scene, const SceneBuffers& buffers);
  // Lays the world program behind every pixel of the frame (its crop) under
  // the resolved `image` (float4 rows) in place, as an opaque film shows it
  // (world_pixels in material_program.cl); nothing without a world program.
  void composite_world(const Scene& scene, const SceneBuffers& buffers, const FrameParams& f, const cl::Buffer& image);
  // Only the alpha (grid_c's w) of the vertices whose programs compute it:
  // what a shadow view needs.
  void alpha(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
             GridBuffers& grids, StageTimer& timer);
  // The budget of the record pool a shading launch hands the light program
  // (mp_surface_record.h): on CPUs, and on other devices, which want more
  // vertices a launch.
  static constexpr size_t kRecordPoolMiB = 32, kRecordPoolGpuMiB = 256;
  // Bytes the record pool holds (at most its budget).
  size_t record_pool_bytes() const { return records_bytes_; }

 private:
  struct Built {
    cl::Program program;
    SceneKernel displace, shade, bake_world, world_pixels;
    bool thin_film = false;       // lit by the light program with thin film
    unsigned long long used = 0;  // the last prepare() that used it
  };
  // The light program (kernels/materials/light_program.cl) without and with
  // thin film: built on first use, then kept for the session.
  struct Light {
    cl::Program program;
    SceneKernel kernel;
  };
  Light& light(bool thin_film, RenderStats& stats);
  std::unique_ptr<Light> light_[2];
  // The record pool (mp_surface_record.h): a range of the batch's vertices
  // at a time, within kRecordPoolMiB.
  cl::Buffer records_;
  size_t records_bytes_ = 0;
  // Programs kept beyond those the current scene uses: node values are
  // parameters (Material::program_params), but a tree whose structure
  // changes (a link made, a node added, a mode switched) builds a new
  // program, and keeping them all would grow without limit (about 8 MiB each
  // on PoCL). A few are kept for scenes that switch back and forth; the rest
  // are rebuilt from the program cache when they return (program_cache.h).
  static constexpr size_t kSparePrograms = 8;
  void evict_unused();
  struct Active {
    Built* built;
    cl_int index;  // the scene's program index, as DeviceMaterial.program[0]
    bool displaces, shades, alpha;
  };
  // The program of a material's tree, or (`world`) of the world's: each
  // holds only its own kernels (material_program.cl).
  Built* build(const MaterialProgram& mp, bool world, const char* owner, RenderStats& stats);
  // One work-item per vertex of the batch's grids.
  void launch(cl::Kernel& kernel, const GridBuffers& grids, Stage stage, StageTimer& timer);
  void run_shade(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene, const FrameParams& f,
                 GridBuffers& grids, const ShadowInputs& shadows, const cl::Buffer& visible, bool alpha_only,
                 StageTimer& timer);

  DeviceSession& session_;
  std::unordered_map<std::string, std::unique_ptr<Built>> built_;  // by kind and source
  unsigned long long generation_ = 0;                               // prepare() calls
  std::vector<Active> active_;
  Built* world_ = nullptr;  // the scene's world program, if any
  bool displaces_ = false;
  SceneKernel normals_;  // displaced_normals, from the main program
};

}  // namespace mp
