#include "pipeline/scene_buffers.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "micropoly/error.h"

#include "mp_patch.h"

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
  d.program[0] = static_cast<float>(m.program);
  d.program[1] = m.program >= 0 && m.program_displaces ? 1.0f : 0.0f;
  d.program[2] = m.program >= 0 && m.program_shades ? 1.0f : 0.0f;
  return d;
}

// Camera <-> object transforms and texture space of one surface.
DeviceObject to_device_object(const glm::mat4& to_camera, glm::vec3 texspace_location, glm::vec3 texspace_size,
                              const std::vector<glm::vec3>& points) {
  if (texspace_size == glm::vec3(0.0f) && !points.empty()) {
    glm::vec3 lo(3e38f), hi(-3e38f);
    for (const glm::vec3& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
    texspace_location = 0.5f * (lo + hi);
    texspace_size = 0.5f * (hi - lo);
  }
  DeviceObject o{};
  const glm::mat4 to_object = glm::inverse(to_camera);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      o.to_object[4 * r + c] = to_object[c][r];  // glm is column-major
      o.to_camera[4 * r + c] = to_camera[c][r];
    }
  put(o.texspace_location, texspace_location, 0.0f);
  put(o.texspace_size, texspace_size, 0.0f);
  return o;
}

// Longest a unit object-space vector can become in camera space.
float max_scale(const glm::mat4& m) {
  return std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
}

// Tags patches [first, size) with their object and, for displaced
// materials, the displacement bound in camera space (mp_patch.h).
void finish_object_patches(PatchBuffer& patches, size_t first, uint32_t object, const Scene& scene, float scale) {
  for (size_t p = first; p < patches.size(); ++p) {
    patches.info[p].z |= object << 8;
    const unsigned mi = patches.info[p].y;
    if (mi < scene.materials.size()) {
      const Material& m = scene.materials[mi];
      if (m.program >= 0 && m.program_displaces) patches.points[p * MP_PATCH_POINTS].w = m.displacement_bound * scale;
    }
  }
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
  d.cone[0] = std::cos(outer), d.cone[1] = std::cos(inner), d.cone[2] = l.beam_distribution, d.cone[3] = 0.0f;
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
  return d;
}

template <typename T>
cl::Buffer upload(cl::Context& context, cl::CommandQueue& queue, const std::vector<T>& v) {
  size_t bytes = std::max<size_t>(v.size() * sizeof(T), 16);  // zero-sized buffers are invalid
  cl::Buffer b(context, CL_MEM_READ_ONLY, bytes);
  if (!v.empty()) queue.enqueueWriteBuffer(b, CL_FALSE, 0, v.size() * sizeof(T), v.data());
  return b;
}

}  // namespace

HostSceneData prepare_scene_data(const Scene& scene) {
  HostSceneData out;
  const glm::mat4& w2c = scene.camera.world_to_camera;
  for (const Mesh& mesh : scene.meshes)
    out.patches.uv_layers = std::max(out.patches.uv_layers, int(mesh.uv_layers.size()));
  // Each surface's patches share their edges' curves (patch_edges.h), so
  // neighbouring patches dice watertight; separate surfaces do not.
  for (const Mesh& mesh : scene.meshes) {
    glm::mat4 to_camera = w2c * mesh.object_to_world;
    const size_t first = out.patches.size();
    if (mesh.scheme == SubdivScheme::CatmullClark)
      append_subdiv_patches(mesh, to_camera, out.patches);
    else
      append_polygon_patches(mesh, to_camera, out.patches);
    share_patch_edges(out.patches, first);
    finish_object_patches(out.patches, first, uint32_t(out.objects.size()), scene, max_scale(to_camera));
    out.objects.push_back(to_device_object(to_camera, mesh.texspace_location, mesh.texspace_size, mesh.points));
  }
  for (const BezierPatches& set : scene.bezier_patches) {
    const size_t first = out.patches.size();
    glm::mat4 to_camera = w2c * set.object_to_world;
    append_bezier_patches(set, to_camera, out.patches);
    share_patch_edges(out.patches, first);
    finish_object_patches(out.patches, first, uint32_t(out.objects.size()), scene, max_scale(to_camera));
    out.objects.push_back(to_device_object(to_camera, glm::vec3(0.0f), glm::vec3(0.0f), set.control_points));
  }
  if (scene.materials.empty()) out.materials.push_back(to_device(Material{}));
  for (const Material& m : scene.materials) out.materials.push_back(to_device(m));
  for (const Light& l : scene.lights) out.lights.push_back(to_device(l, w2c));
  for (const Image& image : scene.images) {
    // DeviceImage offsets are 32-bit texel indices (64 GiB of float texels).
    if (out.texels.size() + image.pixels.size() > size_t(UINT32_MAX))
      throw Error("image '" + image.name + "': the scene's images exceed 2^32 texels");
    out.images.push_back(DeviceImage{uint32_t(out.texels.size()), uint32_t(image.width), uint32_t(image.height),
                                     image.srgb ? 1u : 0u});
    out.texels.insert(out.texels.end(), image.pixels.begin(), image.pixels.end());
  }
  return out;
}

SceneBuffers upload_scene_data(cl::Context& context, cl::CommandQueue& queue, const HostSceneData& data) {
  SceneBuffers b;
  b.points = upload(context, queue, data.patches.points);
  b.patch_info = upload(context, queue, data.patches.info);
  b.patch_edges = upload(context, queue, data.patches.edges);
  b.edge_curves = upload(context, queue, data.patches.curves);
  b.materials = upload(context, queue, data.materials);
  b.objects = upload(context, queue, data.objects);
  b.lights = upload(context, queue, data.lights);
  b.patch_uvs = upload(context, queue, data.patches.uvs);
  b.images = upload(context, queue, data.images);
  b.texels = upload(context, queue, data.texels);
  b.uv_layers = static_cast<cl_uint>(data.patches.uv_layers);
  b.image_count = static_cast<cl_uint>(data.images.size());
  b.patch_count = static_cast<cl_uint>(data.patches.size());
  b.light_count = static_cast<cl_uint>(data.lights.size());
  queue.finish();
  return b;
}

}  // namespace mp
