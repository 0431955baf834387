#include "pipeline/materials/material_programs.h"

#include "cl/kernel_args.h"
#include "cl/program_cache.h"
#include "micropoly/error.h"
#include "materials/mp_surface_record.h"

#include <algorithm>

namespace mp {

void MaterialPrograms::prepare(const Scene& scene, RenderStats& stats) {
  ++generation_;
  active_.clear();
  displaces_ = false;
  std::vector<bool> displaces(scene.material_programs.size(), false), shades(displaces), alpha(displaces);
  for (const Material& m : scene.materials) {
    if (m.program < 0) continue;
    displaces[m.program] = displaces[m.program] || m.program_displaces;
    shades[m.program] = shades[m.program] || m.program_shades;
    alpha[m.program] = alpha[m.program] || (m.program_shades && m.program_alpha);
  }
  for (size_t i = 0; i < scene.material_programs.size(); ++i) {
    if (!displaces[i] && !shades[i]) continue;
    active_.push_back({build(scene.material_programs[i], false, "material '", stats), static_cast<cl_int>(i),
                       static_cast<bool>(displaces[i]), static_cast<bool>(shades[i]), static_cast<bool>(alpha[i])});
    displaces_ = displaces_ || displaces[i];
    if (shades[i]) light(active_.back().built->thin_film, stats);
  }
  const int w = scene.world.program;
  world_ = w >= 0 && size_t(w) < scene.material_programs.size()
               ? build(scene.material_programs[size_t(w)], true, "world '", stats)
               : nullptr;
  evict_unused();
}

void MaterialPrograms::evict_unused() {
  std::vector<std::pair<unsigned long long, const std::string*>> spare;
  for (const auto& [source, built] : built_)
    if (built->used != generation_) spare.emplace_back(built->used, &source);
  if (spare.size() <= kSparePrograms) return;
  std::sort(spare.begin(), spare.end());  // least recently used first
  std::vector<std::string> evict;
  for (size_t i = 0; i + kSparePrograms < spare.size(); ++i) evict.push_back(*spare[i].second);
  for (const std::string& source : evict) built_.erase(source);
}

MaterialPrograms::Built* MaterialPrograms::build(const MaterialProgram& mp, bool world, const char* owner,
                                                 RenderStats& stats) {
  const std::string key = (world ? "world\n" : "material\n") + mp.source;
  auto it = built_.find(key);
  if (it != built_.end()) {
    it->second->used = generation_;
    return it->second.get();
  }
  BuiltProgram b;
  try {
    b = build_program_cached(session_.context(), session_.device(), assemble_material_program_source(mp.source, world),
                             "-cl-std=CL1.2");
  } catch (const Error& e) {
    throw Error(owner + mp.name + "': its node tree did not compile: " + e.what());
  }
  stats.program_build_ms += b.build_ms;
  auto built = std::make_unique<Built>();
  built->program = b.program;
  const std::vector<std::string> switches = material_program_switches(mp.source);
  built->thin_film = std::any_of(switches.begin(), switches.end(), [](const std::string& line) {
    return line.rfind("#define MP_NODE_USES_THIN_FILM", 0) == 0;
  });
  if (world) {
    built->bake_world = SceneKernel(built->program, "bake_world");
    built->world_pixels = SceneKernel(built->program, "world_pixels");
  } else {
    built->displace = SceneKernel(built->program, "displace_grids");
    built->shade = SceneKernel(built->program, "shade_program_grids");
  }
  built->used = generation_;
  return built_.emplace(key, std::move(built)).first->second.get();
}

MaterialPrograms::Light& MaterialPrograms::light(bool thin_film, RenderStats& stats) {
  std::unique_ptr<Light>& l = light_[thin_film ? 1 : 0];
  if (l) return *l;
  BuiltProgram b = build_program_cached(session_.context(), session_.device(),
                                        assemble_light_program_source(thin_film), "-cl-std=CL1.2");
  stats.program_build_ms += b.build_ms;
  l = std::make_unique<Light>();
  l->program = b.program;
  l->kernel = SceneKernel(l->program, "light_program_surfaces");
  return *l;
}

WorldMap MaterialPrograms::bake_world(const Scene& scene, const SceneBuffers& buffers) {
  WorldMap map;
  if (!world_) return map;
  map.width = std::clamp(scene.world.bake_width, 8, 8192);
  map.height = map.width / 2;
  const size_t texels = size_t(map.width) * size_t(map.height);
  cl::Buffer out = session_.allocate(texels * sizeof(cl_float4), "world map");
  cl::Kernel& k = world_->bake_world.bind(buffers, cl_uint(map.width), cl_uint(map.height), out);
  DeviceQueue& q = session_.queue();
  q.enqueueNDRangeKernel(k, cl::NullRange, round_up_range(cl_uint(texels)), cl::NDRange(64));
  std::vector<cl_float4> host(texels);
  q.enqueueReadBuffer(out, CL_TRUE, 0, texels * sizeof(cl_float4), host.data());
  map.radiance.resize(texels);
  for (size_t i = 0; i < texels; ++i) map.radiance[i] = glm::vec3(host[i].s[0], host[i].s[1], host[i].s[2]);
  return map;
}

void MaterialPrograms::composite_world(const Scene& scene, const SceneBuffers& buffers, const FrameParams& f,
                                       const cl::Buffer& image) {
  if (!world_) return;
  const size_t pixels = size_t(f.width) * size_t(f.height);
  // Camera to world: the inverse of the view's rotation, by rows.
  const glm::mat3 to_world = glm::inverse(glm::mat3(scene.camera.world_to_camera));
  auto row = [&](int r) { return cl_float4{{to_world[0][r], to_world[1][r], to_world[2][r], 0.0f}}; };
  cl::Kernel& k = world_->world_pixels.bind(buffers, f, row(0), row(1), row(2), image);
  session_.queue().enqueueNDRangeKernel(k, cl::NullRange, round_up_range(cl_uint(pixels)), cl::NDRange(64));
}

void MaterialPrograms::launch(cl::Kernel& kernel, const GridBuffers& grids, Stage stage, StageTimer& timer) {
  cl::Event e;
  session_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, round_up_range(grids.vertex_total), cl::NDRange(64),
                                        nullptr, &e);
  timer.add(stage, e);
}

void MaterialPrograms::displace(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                                const FrameParams& f, GridBuffers& grids, StageTimer& timer, bool normals) {
  if (!displaces_) return;
  for (Active& a : active_) {
    if (!a.displaces) continue;
    launch(a.built->displace.bind(scene, diceable, count, f, a.index, grids.p, grids.n, grids.vertex_offsets), grids,
           Stage::Dice, timer);
  }
  if (!normals) return;
  launch(normals_.bind(scene, diceable, count, f, grids.p, grids.n, grids.vertex_offsets), grids, Stage::Dice, timer);
}

void MaterialPrograms::shade(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                             const FrameParams& f, GridBuffers& grids, const ShadowInputs& shadows,
                             const cl::Buffer& visible, StageTimer& timer) {
  run_shade(diceable, count, scene, f, grids, shadows, visible, false, timer);
}

void MaterialPrograms::alpha(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                             const FrameParams& f, GridBuffers& grids, StageTimer& timer) {
  run_shade(diceable, count, scene, f, grids, ShadowInputs{}, cl::Buffer(), true, timer);
}

void MaterialPrograms::run_shade(const cl::Buffer& diceable, cl_uint count, const SceneBuffers& scene,
                                 const FrameParams& f, GridBuffers& grids, const ShadowInputs& shadows,
                                 const cl::Buffer& visible, bool alpha_only, StageTimer& timer) {
  if (alpha_only) {
    for (Active& a : active_) {
      if (!a.alpha) continue;
      launch(a.built->shade.bind(scene, diceable, count, f, a.index, grids.p, grids.n, grids.c, grids.vertex_offsets,
                                 cl_uint(1), visible, cl::Buffer(), cl_uint(0)),
             grids, Stage::Shade, timer);
    }
    return;
  }
  if (grids.vertex_total == 0 ||
      std::none_of(active_.begin(), active_.end(), [](const Active& a) { return a.shades; }))
    return;
  // The batch's vertices a range at a time, as many as the record pool's
  // budget holds: each program records its vertices' closures, then the
  // light program lights them, before the next range reuses the pool.
  const size_t budget = (session_.info().type == "cpu" ? kRecordPoolMiB : kRecordPoolGpuMiB) << 20;
  const size_t vertices = (size_t(grids.vertex_total) + 63) / 64 * 64;
  const size_t range = std::min(vertices, std::max<size_t>(64, budget / MP_SURFACE_RECORD_BYTES / 64 * 64));
  session_.reserve(records_, records_bytes_, range * MP_SURFACE_RECORD_BYTES, "material surface records");
  DeviceQueue& q = session_.queue();
  const cl_uint stride = cl_uint(range);
  for (size_t first = 0; first < vertices; first += range) {
    const size_t size = std::min(range, vertices - first);
    for (Active& a : active_) {
      if (!a.shades) continue;
      cl::Event recorded, lit;
      q.enqueueNDRangeKernel(a.built->shade.bind(scene, diceable, count, f, a.index, grids.p, grids.n, grids.c,
                                                 grids.vertex_offsets, cl_uint(0), visible, records_, stride),
                             cl::NDRange(first), cl::NDRange(size), cl::NDRange(64), nullptr, &recorded);
      timer.add(Stage::Shade, recorded);
      q.enqueueNDRangeKernel(light_[a.built->thin_film ? 1 : 0]->kernel.bind(scene, f, grids.p, grids.n, grids.c,
                                                                             shadows.args(), records_, stride,
                                                                             cl_uint(size)),
                             cl::NullRange, cl::NDRange(size), cl::NDRange(64), nullptr, &lit);
      timer.add(Stage::Shade, lit);
    }
  }
}

}  // namespace mp
