#include "pipeline/device_scene/scene_buffers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cl/device_session.h"
#include "micropoly/error.h"

#include "cl/kernel_args.h"
#include "geometry/mp_patch.h"
#include "pipeline/device_scene/instance_placement.h"
#include "pipeline/device_scene/shape_placement.h"
#include "pipeline/pass/stage_timer.h"
#include "textures/mp_tex_image.h"
#include "closures/mp_world.h"

namespace mp {
namespace {

void put(float* dst, glm::vec3 v, float w) {
  dst[0] = v.x, dst[1] = v.y, dst[2] = v.z, dst[3] = w;
}

DeviceMaterial to_device(const Material& m) {
  DeviceMaterial d{};
  float model = m.model == Material::Model::Constant ? MP_MODEL_CONSTANT
                : m.model == Material::Model::Matte  ? MP_MODEL_MATTE
                : m.model == Material::Model::Plastic ? MP_MODEL_PLASTIC
                                                      : MP_MODEL_PRINCIPLED;
  put(d.color, m.color, model);
  float avg = std::clamp((m.opacity.x + m.opacity.y + m.opacity.z) / 3.0f, 0.0f, 1.0f);
  put(d.opacity, m.opacity, avg);
  d.coeffs[0] = m.ka, d.coeffs[1] = m.kd, d.coeffs[2] = m.ks, d.coeffs[3] = m.roughness;
  put(d.specular, m.specular_color, 0.0f);
  put(d.emission, m.emission, 0.0f);
  d.principled[0] = std::clamp(m.metallic, 0.0f, 1.0f);
  d.principled[1] = std::max(m.specular, 0.0f);
  d.principled[2] = m.layered ? 1.0f : 0.0f;
  d.principled[3] = (m.retro_diffuse ? 1.0f : 0.0f) + (m.multiscatter ? 2.0f : 0.0f);
  d.program[0] = static_cast<float>(m.program);
  d.program[1] = m.program >= 0 && m.program_displaces ? 1.0f : 0.0f;
  d.program[2] = m.program >= 0 && m.program_shades ? 1.0f : 0.0f;
  // 2: the alpha is a hard cut (Material::program_alpha_cut; mp_quad_cut).
  d.program[3] = m.program >= 0 && m.program_shades && m.program_alpha ? (m.program_alpha_cut ? 2.0f : 1.0f) : 0.0f;
  return d;
}

// Node values of a material (or the world) appended to the scene's
// parameter buffer; returns where they start.
uint32_t append_params(const std::vector<float>& values, const std::string& owner, std::vector<float>& params) {
  if (params.size() + values.size() > size_t(UINT32_MAX))
    throw Error(owner + ": the scene's node values exceed 2^32");
  const uint32_t at = uint32_t(params.size());
  params.insert(params.end(), values.begin(), values.end());
  return at;
}

// Motion blur: every surface's control points and edge curves in camera
// space at each motion step (its points rebuilt into the same patches where
// it deforms), and each patch's reach: how far (per camera axis) any of its
// control points moves away from the shutter centre's, in w of its control
// points 1 to 3 (MP_PATCH_MOTION_REACH), which bounds keep for culling.
void place_motion(const Scene& scene, const std::vector<PatchCache::Surface>& surfaces, PatchCache* cache,
                  HostSceneData& out) {
  const size_t steps = size_t(scene.motion_steps);
  out.motion_steps = scene.motion_steps;
  out.motion_points.reserve(steps * out.patches.points.size());
  out.motion_curves.reserve(steps * out.patches.curves.size());
  std::vector<Mesh> moved(scene.meshes.size());
  std::vector<BezierPatches> moved_sets(scene.bezier_patches.size());
  for (size_t k = 0; k < steps; ++k) {
    std::vector<PatchCache::Surface> at_step = surfaces;
    for (size_t i = 0; i < scene.meshes.size(); ++i)
      if (!scene.meshes[i].motion_points.empty()) {
        moved[i] = scene.meshes[i];
        moved[i].points = scene.meshes[i].motion_points[k];
        at_step[i].mesh = &moved[i];
      }
    // Patch sets follow the meshes in `surfaces`.
    for (size_t j = 0; j < scene.bezier_patches.size(); ++j)
      if (!scene.bezier_patches[j].motion_control_points.empty()) {
        moved_sets[j] = scene.bezier_patches[j];
        moved_sets[j].control_points = scene.bezier_patches[j].motion_control_points[k];
        at_step[scene.meshes.size() + j].set = &moved_sets[j];
      }
    const auto shapes = cache->shapes(at_step, out.patches.uv_layers);
    const glm::mat4& w2c = scene.camera.motion_world_to_camera.empty() ? scene.camera.world_to_camera
                                                                        : scene.camera.motion_world_to_camera[k];
    for (size_t i = 0; i < surfaces.size(); ++i) {
      const Mesh* mesh = surfaces[i].mesh;
      const BezierPatches* set = surfaces[i].set;
      const glm::mat4& o2w = mesh ? (mesh->motion_object_to_world.empty() ? mesh->object_to_world
                                                                          : mesh->motion_object_to_world[k])
                                  : (set->motion_object_to_world.empty() ? set->object_to_world
                                                                         : set->motion_object_to_world[k]);
      place_positions(*shapes[i], w2c * o2w, out.motion_points, out.motion_curves);
    }
    if (out.motion_points.size() != (k + 1) * out.patches.points.size() ||
        out.motion_curves.size() != (k + 1) * out.patches.curves.size())
      throw Error("motion step " + std::to_string(k) + " changes the scene's patches (a topology that moves?)");
  }
  const size_t n = out.patches.points.size();
  for (size_t p = 0; p < out.patches.size(); ++p) {
    glm::vec3 reach(0.0f);
    for (size_t k = 0; k < steps; ++k)
      for (size_t c = 0; c < MP_PATCH_POINTS; ++c) {
        const size_t i = p * MP_PATCH_POINTS + c;
        reach = glm::max(reach, glm::abs(glm::vec3(out.motion_points[k * n + i]) - glm::vec3(out.patches.points[i])));
      }
    for (int a = 0; a < 3; ++a) out.patches.points[p * MP_PATCH_POINTS + 1 + size_t(a)].w = reach[a];
  }
}

// The environment light's two records (kernels/closures/mp_shading.h,
// mp_env_irradiance): camera -> world rotation rows, then the coefficients.
void put_environment(const Light& l, const glm::mat4& world_to_camera, std::vector<DeviceLight>& out) {
  DeviceLight r[2]{};
  put(r[0].color, l.color, float(MP_LIGHT_ENVIRONMENT));
  r[1].color[3] = float(MP_LIGHT_ENVIRONMENT_DATA);
  auto slot = [&](int i) -> float& {
    static_assert(sizeof(DeviceLight) == 24 * sizeof(float), "DeviceLight is 24 floats");
    float* f = reinterpret_cast<float*>(r);  // floats 4..23 of each record, past its colour
    return i < 20 ? f[4 + i] : f[28 + (i - 20)];
  };
  // world_to_camera is rigid (scaled at most uniformly): its inverse's
  // linear part is the normalised transpose.
  glm::mat3 to_camera(world_to_camera);
  for (int c = 0; c < 3; ++c) to_camera[c] = glm::normalize(to_camera[c]);
  const glm::mat3 to_world = glm::transpose(to_camera);
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) slot(3 * row + col) = to_world[col][row];
  for (size_t k = 0; k < l.irradiance_sh.size() && k < 27; ++k) slot(9 + int(k)) = l.irradiance_sh[k];
  out.push_back(r[0]);
  out.push_back(r[1]);
}

DeviceLight to_device(const Light& l, const glm::mat4& world_to_camera) {
  DeviceLight d{};
  int type = l.type == Light::Type::Ambient   ? MP_LIGHT_AMBIENT
             : l.type == Light::Type::Distant ? MP_LIGHT_DISTANT
             : l.type == Light::Type::Point   ? MP_LIGHT_POINT
             : l.type == Light::Type::Spot    ? MP_LIGHT_SPOT
                                              : MP_LIGHT_AREA;
  put(d.color, l.color * l.intensity, static_cast<float>(type));
  put(d.position, glm::vec3(world_to_camera * glm::vec4(l.position, 1.0f)), 1.0f);
  glm::vec3 dir = glm::vec3(world_to_camera * glm::vec4(l.direction, 0.0f));
  float len = glm::length(dir);
  put(d.direction, len > 0.0f ? dir / len : glm::vec3(0, 0, -1), 0.0f);
  float outer = std::clamp(l.cone_angle, 0.0f, 3.14159265f);
  float inner = std::clamp(l.cone_angle - l.cone_delta_angle, 0.0f, outer);
  d.cone[0] = std::cos(outer), d.cone[1] = std::cos(inner), d.cone[2] = l.beam_distribution;
  // A point or spot light's radius, and whether it is a sphere rather than
  // a disk facing the lit point (mp_shading.h).
  const bool sized = l.type == Light::Type::Point || l.type == Light::Type::Spot;
  d.cone[3] = sized ? l.radius : 0.0f;
  d.direction[3] = sized && !l.soft_falloff ? 1.0f : 0.0f;
  if (l.type == Light::Type::Area) {
    // Half extents in camera space; v completes a right-handed frame with the
    // emission direction.
    glm::vec3 n = glm::normalize(glm::vec3(l.direction));
    glm::vec3 u = l.axis_u - n * glm::dot(l.axis_u, n);
    u = glm::length(u) > 0.0f ? glm::normalize(u) : glm::normalize(glm::cross(n, glm::vec3(n.z, n.x, n.y)));
    glm::vec3 v = glm::cross(n, u);
    glm::vec3 hu = glm::vec3(world_to_camera * glm::vec4(u * (0.5f * l.size_u), 0.0f));
    glm::vec3 hv = glm::vec3(world_to_camera * glm::vec4(v * (0.5f * l.size_v), 0.0f));
    put(d.axis_u, hu, l.shape == Light::Shape::Ellipse ? float(MP_AREA_ELLIPSE) : float(MP_AREA_RECTANGLE));
    put(d.axis_v, hv, 0.0f);
  }
  if (l.world_probe) d.axis_u[3] = MP_WORLD_PROBE;
  return d;
}

// Each patch's box (camera space): its control points' (Gregory partners
// included, so the surface lies inside), grown by its displacement bound.
std::vector<glm::vec4> patch_bounds(const PatchBuffer& patches) {
  std::vector<glm::vec4> out(2 * patches.size());
  for (size_t p = 0; p < patches.size(); ++p) {
    const glm::vec4* cp = &patches.points[p * MP_PATCH_POINTS];
    glm::vec3 lo(cp[0]), hi(cp[0]);
    for (int k = 1; k < MP_PATCH_POINTS; ++k) lo = glm::min(lo, glm::vec3(cp[k])), hi = glm::max(hi, glm::vec3(cp[k]));
    // MP_PATCH_DISPLACEMENT_BOUND and MP_PATCH_MOTION_REACH.
    const glm::vec3 reach = glm::vec3(cp[0].w) + glm::vec3(cp[1].w, cp[2].w, cp[3].w);
    out[2 * p] = glm::vec4(lo - reach, 0.0f);
    out[2 * p + 1] = glm::vec4(hi + reach, 0.0f);
  }
  return out;
}

template <typename T>
cl::Buffer upload(DeviceSession& session, const std::vector<T>& v) {
  // allocate() pads to 16 bytes: zero-sized buffers are invalid.
  cl::Buffer b = session.allocate(v.size() * sizeof(T), "scene data", CL_MEM_READ_ONLY);
  if (!v.empty()) session.queue().enqueueWriteBuffer(b, CL_FALSE, 0, v.size() * sizeof(T), v.data());
  return b;
}

// The writes above do not block: if the upload fails part way, the ones
// already queued may still read the host arrays, which unwinding is about
// to free, so the queue is drained before the error goes on.
template <typename F>
void upload_or_drain(DeviceSession& session, F&& body) {
  try {
    body();
  } catch (...) {
    session.queue().drain();
    throw;
  }
}

// Every image's level 0 where its DeviceImage says, then its other MIP
// levels, each reduced from the one above on the device.
cl::Buffer upload_images(DeviceSession& session, const HostSceneData& data) {
  cl::Buffer b = session.allocate(data.device_texels * sizeof(glm::vec4), "image texels");
  size_t from = 0;
  for (const DeviceImage& im : data.images) {
    const size_t n = size_t(im.width) * im.height;
    session.queue().enqueueWriteBuffer(b, CL_FALSE, size_t(im.offset) * sizeof(glm::vec4), n * sizeof(glm::vec4),
                                       data.texels.data() + from);
    from += n;
  }
  if (data.images.empty()) return b;
  cl::Kernel reduce(session.program(), "reduce_image_level");
  for (const DeviceImage& im : data.images) {
    const uint32_t levels = mp_image_levels(im.width, im.height);
    for (uint32_t l = 1; l < levels; ++l) {
      const DeviceImage above = mp_image_level(im, l - 1), level = mp_image_level(im, l);
      bind_args(reduce, b, above, level, cl_uint(l == 1 ? 1 : 0));
      session.queue().enqueueNDRangeKernel(reduce, cl::NullRange, round_up_range(size_t(level.width) * level.height),
                                           cl::NDRange(64));
    }
  }
  return b;
}

}  // namespace

std::vector<DeviceLight> device_lights(const std::vector<Light>& lights, const glm::mat4& world_to_camera) {
  std::vector<DeviceLight> out;
  for (const Light& l : lights) {
    if (l.type == Light::Type::Environment)
      put_environment(l, world_to_camera, out);
    else
      out.push_back(to_device(l, world_to_camera));
  }
  return out;
}

HostSceneData prepare_scene_data(const Scene& scene, PatchCache* cache) {
  HostSceneData out;
  const glm::mat4& w2c = scene.camera.world_to_camera;
  auto attribute_slots = [&](const ObjectInfo& info) {
    out.object_attribute_count = std::max(out.object_attribute_count, uint32_t(info.attributes.size()));
  };
  for (const Mesh& mesh : scene.meshes) attribute_slots(mesh.info);
  for (const BezierPatches& set : scene.bezier_patches) attribute_slots(set.info);
  for (const Instance& inst : scene.instances) attribute_slots(inst.info);
  for (const Mesh& mesh : scene.meshes)
    out.patches.uv_layers = std::max(out.patches.uv_layers, int(mesh.uv_layers.size()));
  for (const BezierPatches& set : scene.bezier_patches)
    out.patches.uv_layers = std::max(out.patches.uv_layers, int(set.uv_layers.size()));
  for (const Prototype& proto : scene.prototypes) {
    for (const Mesh& mesh : proto.meshes)
      out.patches.uv_layers = std::max(out.patches.uv_layers, int(mesh.uv_layers.size()));
    for (const BezierPatches& set : proto.bezier_patches)
      out.patches.uv_layers = std::max(out.patches.uv_layers, int(set.uv_layers.size()));
  }
  // Each surface's patches share their edges' curves (patch_edges.h), so
  // neighbouring patches dice watertight; separate surfaces do not.
  std::vector<PatchCache::Surface> surfaces;
  for (const Mesh& mesh : scene.meshes) surfaces.push_back({&mesh, nullptr});
  for (const BezierPatches& set : scene.bezier_patches) surfaces.push_back({nullptr, &set});
  // The prototypes' surfaces are built in the same call (the cache keeps
  // what its last two calls used).
  const PrototypeVariants variants = prototype_variants(scene);
  std::vector<PatchCache::Surface> all = surfaces;
  all.insert(all.end(), variants.surfaces.begin(), variants.surfaces.end());
  PatchCache local;
  auto shapes = (cache ? cache : &local)->shapes(all, out.patches.uv_layers);
  const std::vector<std::shared_ptr<const PatchBuffer>> prototype_shapes(shapes.begin() + long(surfaces.size()),
                                                                         shapes.end());
  shapes.resize(surfaces.size());
  // Reserved once for all surfaces: growing per surface to its exact size
  // would copy everything placed so far for every object (quadratic in the
  // object count; thousands of instances took minutes).
  size_t totals[6] = {};
  for (const auto& shape : shapes) {
    totals[0] += shape->points.size(), totals[1] += shape->info.size(), totals[2] += shape->edges.size();
    totals[3] += shape->curves.size(), totals[4] += shape->uvs.size(), totals[5] += shape->normals.size();
  }
  out.patches.points.reserve(totals[0]), out.patches.info.reserve(totals[1]), out.patches.edges.reserve(totals[2]);
  out.patches.curves.reserve(totals[3]), out.patches.uvs.reserve(totals[4]), out.patches.normals.reserve(totals[5]);
  out.objects.reserve(surfaces.size());
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Mesh* mesh = surfaces[i].mesh;
    const BezierPatches* set = surfaces[i].set;
    const glm::mat4 to_camera = w2c * (mesh ? mesh->object_to_world : set->object_to_world);
    place_shape(*shapes[i], to_camera, mesh, set, uint32_t(out.objects.size()), scene, out.patches);
    const glm::mat4& to_world = mesh ? mesh->object_to_world : set->object_to_world;
    const ObjectInfo& info = mesh ? mesh->info : set->info;
    out.add_object(mesh ? to_device_object(to_camera, to_world, mesh->texspace_location, mesh->texspace_size,
                                           mesh->points, info)
                        : to_device_object(to_camera, to_world, glm::vec3(0.0f), glm::vec3(0.0f),
                                           set->control_points, info),
                   info);
  }
  if (scene.motion_steps >= 2) place_motion(scene, surfaces, cache ? cache : &local, out);
  out.own_patches = out.root_count = out.patches.size();
  place_instances(scene, variants, prototype_shapes, out);
  if (scene.materials.empty()) out.materials.push_back(to_device(Material{}));
  for (const Material& m : scene.materials) {
    DeviceMaterial d = to_device(m);
    d.params[0] = append_params(m.program_params, "material '" + m.name + "'", out.params);
    d.params[1] = uint32_t(m.program_params.size());
    out.materials.push_back(d);
  }
  out.world_params_at = append_params(scene.world.program_params, "the world", out.params);
  if (out.params.empty()) out.params.push_back(0.0f);  // a buffer of at least one value
  if (out.object_attributes.empty()) out.object_attributes.emplace_back(0.0f);
  out.lights = device_lights(scene.lights, w2c);
  std::vector<bool> refracts(out.materials.size(), false);
  for (size_t k = 0; k < scene.materials.size(); ++k) {
    const Material& m = scene.materials[k];
    refracts[k] = m.program_shades && m.program >= 0 && size_t(m.program) < scene.material_programs.size() &&
                  program_refracts(scene.material_programs[size_t(m.program)].source, m.program_params);
  }
  out.refraction = build_refraction_proxies(out.patches, out.objects.size(), refracts);
  for (const Image& image : scene.images) {
    // DeviceImage offsets are 32-bit texel indices (64 GiB of float texels),
    // counting each image's MIP levels (a third more than its pixels).
    const size_t levels = size_t(mp_image_texel_count(uint32_t(image.width), uint32_t(image.height)));
    if (out.device_texels + levels > size_t(UINT32_MAX))
      throw Error("image '" + image.name + "': the scene's images and their MIP levels exceed 2^32 texels");
    out.images.push_back(DeviceImage{uint32_t(out.device_texels), uint32_t(image.width), uint32_t(image.height),
                                     image.srgb ? 1u : 0u});
    out.texels.insert(out.texels.end(), image.pixels.begin(), image.pixels.end());
    out.device_texels += levels;
  }
  return out;
}

void upload_lights(DeviceSession& session, const std::vector<Light>& lights, const glm::mat4& world_to_camera,
                   SceneBuffers& buffers) {
  const std::vector<DeviceLight> records = device_lights(lights, world_to_camera);
  upload_or_drain(session, [&] {
    buffers.lights = upload(session, records);
    buffers.light_count = static_cast<cl_uint>(records.size());
    buffers.version = session.next_data_version();
    session.queue().finish();  // `records` lives only for the call
  });
}

cl::Buffer prefilter_world_glossy(DeviceSession& session, const WorldMap& map) {
  const size_t texels = size_t(mp_world_glossy_offset(MP_WORLD_GLOSSY_LEVELS));
  cl::Buffer out = session.allocate(texels * sizeof(glm::vec4), "world glossy maps");
  DeviceQueue& q = session.queue();
  const std::vector<glm::vec4> mips = world_map_mips(map);
  upload_or_drain(session, [&] {
    if (mips.empty()) {
      q.enqueueFillBuffer(out, cl_float(0.0f), 0, texels * sizeof(glm::vec4));
    } else {
      cl::Buffer source = upload(session, mips);
      cl::Kernel k(session.program(), "prefilter_world_glossy");
      bind_args(k, source, cl_int(map.width), cl_int(map.height), out);
      q.enqueueNDRangeKernel(k, cl::NullRange, round_up_range(texels), cl::NDRange(64));
    }
    q.finish();  // `mips` lives only for the call
  });
  return out;
}

void set_world_glossy(DeviceSession& session, const cl::Buffer& maps, SceneBuffers& buffers) {
  buffers.world_glossy = maps;
  buffers.version = session.next_data_version();
}

SceneBuffers upload_scene_data(DeviceSession& session, const HostSceneData& data) {
  SceneBuffers b;
  // Read by writes that do not block: they must live until the finish
  // below, or until upload_or_drain has drained the queue after a failure
  // (so they are made out here, not in the body that unwinding leaves).
  const std::vector<glm::vec4> no_world_glossy(1, glm::vec4(0.0f));
  // Every patch's box (the prototypes' in their own space); the host keeps
  // those of the patches placed on their own, which its root orders sort.
  const std::vector<glm::vec4> bounds = patch_bounds(data.patches);
  upload_or_drain(session, [&] {
    b.points = upload(session, data.patches.points);
    b.patch_info = upload(session, data.patches.info);
    b.patch_edges = upload(session, data.patches.edges);
    b.edge_curves = upload(session, data.patches.curves);
    b.materials = upload(session, data.materials);
    b.objects = upload(session, data.objects);
    b.object_attributes = upload(session, data.object_attributes);
    b.object_attribute_count = static_cast<cl_uint>(data.object_attribute_count);
    b.lights = upload(session, data.lights);
    b.patch_uvs = upload(session, data.patches.uvs);
    b.patch_normals = upload(session, data.patches.normals);
    b.patch_bounds = upload(session, bounds);
    b.instances = upload(session, data.instances);
    b.patch_nodes = upload(session, data.patch_nodes);
    b.tree_depth = data.tree_depth;
    b.placed_patches = data.own_patches + data.instanced_patches;
    b.images = upload(session, data.images);
    b.texels = upload_images(session, data);
    b.node_params = upload(session, data.params);
    b.world_params_at = static_cast<cl_uint>(data.world_params_at);
    b.world_glossy = upload(session, no_world_glossy);
    b.motion_points = upload(session, data.motion_points);
    b.motion_curves = upload(session, data.motion_curves);
    b.instance_motion = upload(session, data.instance_motion);
    b.refract_roots = upload(session, data.refraction.roots);
    b.refract_nodes = upload(session, data.refraction.nodes);
    b.refract_tris = upload(session, data.refraction.tris);
    b.motion_steps = static_cast<cl_uint>(data.motion_steps);
    b.point_count = static_cast<cl_uint>(data.patches.points.size());
    b.curve_count = static_cast<cl_uint>(data.patches.curves.size());
    b.uv_layers = static_cast<cl_uint>(data.patches.uv_layers);
    b.image_count = static_cast<cl_uint>(data.images.size());
    b.patch_count = static_cast<cl_uint>(data.own_patches);
    b.root_count = static_cast<cl_uint>(data.root_count);
    b.instance_count = static_cast<cl_uint>(data.instances.size());
    b.light_count = static_cast<cl_uint>(data.lights.size());
    b.version = session.next_data_version();
    session.queue().finish();
    b.host_patch_bounds.assign(bounds.begin(), bounds.begin() + long(2 * data.own_patches));
    for (const DeviceInstance& in : data.instances) {
      b.host_instance_bounds.emplace_back(in.box_lo[0], in.box_lo[1], in.box_lo[2], 0.0f);
      b.host_instance_bounds.emplace_back(in.box_hi[0], in.box_hi[1], in.box_hi[2], 0.0f);
    }
    auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
    b.bytes = bytes(data.patches.points) + bytes(data.patches.info) + bytes(data.patches.edges) +
              bytes(data.patches.curves) + bytes(data.patches.uvs) + bytes(data.patches.normals) + bytes(bounds) +
              bytes(data.objects) + bytes(data.object_attributes) + bytes(data.instances) +
              bytes(data.patch_nodes) + bytes(data.instance_motion) +
              bytes(data.motion_points) + bytes(data.motion_curves);
  });
  return b;
}

}  // namespace mp
