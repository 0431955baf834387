// Shared by the patch builders: topology checks, per-patch info and the
// transform of a 20-point device patch into a PatchBuffer.
#pragma once

#include <array>
#include <cmath>
#include <string>

#include <glm/glm.hpp>

#include "micropoly/error.h"
#include "micropoly/scene.h"
#include "geometry/mp_patch.h"
#include "subdiv/patch_buffer.h"

namespace mp::subdiv_detail {

// A device patch in double precision before the transform: the 4x4 Bezier
// net cp[4*j + i] followed by the partners of the four interior points.
using DevicePatch = std::array<glm::dvec3, MP_PATCH_POINTS>;

// Per-object values every patch of the object shares.
struct PatchInfoCommon {
  glm::dmat4 to_space;
  unsigned flags = 0;
};

inline PatchInfoCommon make_patch_info_common(const glm::mat4& to_space, bool double_sided) {
  PatchInfoCommon c;
  c.to_space = glm::dmat4(to_space);
  if (double_sided) c.flags |= MP_PATCH_DOUBLE_SIDED;
  // A mirroring transform turns counter-clockwise faces clockwise; the
  // pipeline flips the geometric normal instead of reordering control points.
  if (glm::determinant(c.to_space) < 0.0) c.flags |= MP_PATCH_FLIP_ORIENTATION;
  return c;
}

// Corner UVs of one patch for every UV layer: corner (0,0), (1,0), (1,1),
// (0,1) of layer k at [4k .. 4k+3]; null for a patch without UVs (zeros).
// Corner normals likewise (4, object space), null for none.
inline void append_device_patch(const DevicePatch& patch, unsigned type, int material, int prim_id,
                                const PatchInfoCommon& common, PatchBuffer& out,
                                const glm::vec2* corner_uvs = nullptr, const glm::dvec3* corner_normals = nullptr) {
  // Normals map by the inverse transpose; the kernels normalise them.
  const glm::dmat3 normal_map = glm::transpose(glm::inverse(glm::dmat3(common.to_space)));
  for (int c = 0; c < 4; ++c) {
    const glm::dvec3 n = corner_normals ? normal_map * corner_normals[c] : glm::dvec3(0.0);
    out.normals.emplace_back(float(n.x), float(n.y), float(n.z), 0.0f);
  }
  for (const glm::dvec3& p : patch) {
    glm::dvec4 q = common.to_space * glm::dvec4(p, 1.0);
    out.points.emplace_back(float(q.x), float(q.y), float(q.z), 0.0f);  // w: displacement bound (mp_patch.h)
  }
  out.info.emplace_back(type, unsigned(material), common.flags | (corner_normals ? MP_PATCH_SMOOTH_NORMALS : 0u),
                        unsigned(prim_id));
  for (int k = 0; k < out.uv_layers; ++k) {
    if (corner_uvs == nullptr) {
      out.uvs.emplace_back(0.0f), out.uvs.emplace_back(0.0f);
      continue;
    }
    const glm::vec2* c = corner_uvs + 4 * k;
    out.uvs.emplace_back(c[0].x, c[0].y, c[1].x, c[1].y);
    out.uvs.emplace_back(c[2].x, c[2].y, c[3].x, c[3].y);
  }
}

// The mesh's UV of layer k at face corner `corner` (face_vertex_indices
// order), zero where the mesh has fewer layers.
inline glm::vec2 corner_uv(const Mesh& mesh, int k, size_t corner) {
  return size_t(k) < mesh.uv_layers.size() ? mesh.uv_layers[size_t(k)][corner] : glm::vec2(0.0f);
}

// Bezier partners are the interior points themselves (mp_patch.h).
inline void set_bezier_partners(DevicePatch& patch) {
  patch[16] = patch[MP_INTERIOR_0];
  patch[17] = patch[MP_INTERIOR_1];
  patch[18] = patch[MP_INTERIOR_2];
  patch[19] = patch[MP_INTERIOR_3];
}

inline int face_material(const Mesh& mesh, size_t face) {
  return mesh.face_materials.empty() ? mesh.material : mesh.face_materials[face];
}

[[noreturn]] inline void throw_mesh_error(const Mesh& mesh, const std::string& what) {
  throw Error("mesh '" + mesh.name + "': " + what);
}

// Face counts, vertex indices and per-face arrays must be consistent before
// any builder walks them (validate_scene checks this too; the builders do not
// rely on it).
inline void check_face_topology(const Mesh& mesh) {
  size_t total = 0;
  for (int n : mesh.face_vertex_counts) {
    if (n < 3) throw_mesh_error(mesh, "a face has fewer than 3 vertices");
    total += size_t(n);
  }
  if (total != mesh.face_vertex_indices.size())
    throw_mesh_error(mesh, "face vertex counts do not match the number of face vertex indices");
  for (int v : mesh.face_vertex_indices)
    if (v < 0 || size_t(v) >= mesh.points.size())
      throw_mesh_error(mesh, "face vertex index " + std::to_string(v) + " is out of range");
  if (!mesh.face_materials.empty() && mesh.face_materials.size() != mesh.face_vertex_counts.size())
    throw_mesh_error(mesh, "face_materials must have one entry per face");
  for (int m : mesh.face_materials)
    if (m < 0) throw_mesh_error(mesh, "negative face material index");
  if (mesh.material < 0) throw_mesh_error(mesh, "negative material index");
  for (const glm::vec3& p : mesh.points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw_mesh_error(mesh, "a point is not finite");
  for (const std::vector<glm::vec2>& layer : mesh.uv_layers) {
    if (layer.size() != total) throw_mesh_error(mesh, "a UV map needs one (u, v) per face corner");
    for (const glm::vec2& uv : layer)
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) throw_mesh_error(mesh, "a UV is not finite");
  }
}

}  // namespace mp::subdiv_detail
