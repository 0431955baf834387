#include "pipeline/device_scene/shape_placement.h"

#include <algorithm>

#include "geometry/mp_patch.h"

namespace mp {
namespace {

void put4(float* dst, glm::vec3 v, float w) { dst[0] = v.x, dst[1] = v.y, dst[2] = v.z, dst[3] = w; }

}  // namespace

// Camera <-> object transforms and texture space of one surface.
DeviceObject to_device_object(const glm::mat4& to_camera, const glm::mat4& to_world, glm::vec3 texspace_location,
                              glm::vec3 texspace_size, const std::vector<glm::vec3>& points, const ObjectInfo& info) {
  if (texspace_size == glm::vec3(0.0f) && !points.empty()) {
    glm::vec3 lo(3e38f), hi(-3e38f);
    for (const glm::vec3& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
    texspace_location = 0.5f * (lo + hi);
    texspace_size = 0.5f * (hi - lo);
  }
  DeviceObject o{};
  const glm::mat4 to_object = glm::inverse(to_camera);
  const glm::mat4 from_world = glm::inverse(to_world);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      o.to_object[4 * r + c] = to_object[c][r];  // glm is column-major
      o.to_camera[4 * r + c] = to_camera[c][r];
      o.to_world[4 * r + c] = to_world[c][r];
      o.from_world[4 * r + c] = from_world[c][r];
    }
  put4(o.texspace_location, texspace_location, 0.0f);
  put4(o.texspace_size, texspace_size, 0.0f);
  for (int k = 0; k < 4; ++k) o.color[k] = info.color[k];
  o.info[0] = info.pass_index;
  o.info[1] = info.random;
  return o;
}

// Longest a unit object-space vector can become in camera space.
float max_scale(const glm::mat4& m) {
  return std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
}

// Appends an object-space shape's control points and edge curves carried to
// camera space: points by `to_camera`, the curves' normal halves by its
// inverse transpose (the kernels normalise them and orient them like the
// patch, so their scale and sign do not matter).
void place_positions(const PatchBuffer& shape, const glm::mat4& to_camera, std::vector<glm::vec4>& points,
                     std::vector<glm::vec4>& curves) {
  const glm::dmat4 m(to_camera);
  const glm::dmat3 normal_map = glm::transpose(glm::inverse(glm::dmat3(m)));
  auto point = [&](const glm::vec4& p) {
    const glm::dvec4 q = m * glm::dvec4(glm::dvec3(p), 1.0);
    return glm::vec4(float(q.x), float(q.y), float(q.z), 0.0f);
  };
  for (const glm::vec4& p : shape.points) points.push_back(point(p));
  for (size_t c = 0; c < shape.curves.size(); c += MP_CURVE_FLOAT4S) {
    for (int k = 0; k < 4; ++k) curves.push_back(point(shape.curves[c + size_t(k)]));
    for (int k = 4; k < MP_CURVE_FLOAT4S; ++k) {
      const glm::dvec3 n = normal_map * glm::dvec3(glm::vec3(shape.curves[c + size_t(k)]));
      curves.emplace_back(float(n.x), float(n.y), float(n.z), 0.0f);
    }
  }
}

// Appends an object-space shape (patch_cache.h) as object `object`: control
// points and edge curves carried to camera space, edge-curve references
// rebased, and the object's materials (per face through the patch's
// primitive id), sidedness and displacement bound filled in.
void place_shape(const PatchBuffer& shape, const glm::mat4& to_camera, const Mesh* mesh, const BezierPatches* set,
                 uint32_t object, const Scene& scene, PatchBuffer& out) {
  const glm::dmat4 m(to_camera);
  // Shading normals map by the inverse transpose.
  const glm::dmat3 normal_map = glm::transpose(glm::inverse(glm::dmat3(m)));
  unsigned flags = object << 8;
  if (mesh ? mesh->double_sided : set->double_sided) flags |= MP_PATCH_DOUBLE_SIDED;
  if (!(mesh ? mesh->cast_shadows : set->cast_shadows)) flags |= MP_PATCH_NO_SHADOW;
  if (!(mesh ? mesh->visible_camera : set->visible_camera)) flags |= MP_PATCH_NO_CAMERA;
  const int set_material = set ? set->material : 0;
  // A mirroring transform turns counter-clockwise faces clockwise; the
  // pipeline flips the geometric normal instead of reordering control points.
  if (glm::determinant(glm::dmat3(m)) < 0.0) flags |= MP_PATCH_FLIP_ORIENTATION;
  const float bound_scale = max_scale(to_camera);
  const size_t first = out.size();
  const uint32_t curve_base = uint32_t(out.curves.size() / MP_CURVE_FLOAT4S);
  place_positions(shape, to_camera, out.points, out.curves);
  for (size_t p = 0; p < shape.size(); ++p) {
    glm::uvec4 info = shape.info[p];
    const int material = mesh ? (mesh->face_materials.empty() ? mesh->material : mesh->face_materials[info.w])
                              : set_material;
    info.y = unsigned(material);
    info.z = flags | (info.z & MP_PATCH_SHAPE_FLAGS);
    out.info.push_back(info);
    if (info.x == MP_PATCH_CURVE) bound_ribbon(&out.points[(first + p) * MP_PATCH_POINTS]);
    if (size_t(material) < scene.materials.size()) {
      const Material& mat = scene.materials[size_t(material)];
      if (mat.program >= 0 && mat.program_displaces)
        out.points[(first + p) * MP_PATCH_POINTS].w =
            mat.displacement_bound * (mat.displacement_bound_world ? 1.0f : bound_scale);  // camera = world units
    }
  }
  for (uint32_t ref : shape.edges) out.edges.push_back(ref == MP_NO_CURVE ? ref : ref + (curve_base << 1));
  out.uvs.insert(out.uvs.end(), shape.uvs.begin(), shape.uvs.end());
  for (const glm::vec4& n : shape.normals) {
    const glm::dvec3 m = normal_map * glm::dvec3(glm::vec3(n));
    out.normals.emplace_back(float(m.x), float(m.y), float(m.z), 0.0f);
  }
}

}  // namespace mp
