// Flat polygon meshes as device patches.
//
// A quad (v0, v1, v2, v3) is the bilinear patch with u running v0 -> v1 and
// v running v0 -> v3. Degree elevation of a bilinear patch to bicubic puts the
// Bezier control point b_ij at the bilinear point (i/3, j/3), so the net
// reproduces the bilinear surface exactly (Farin, "Curves and Surfaces for
// CAGD", degree elevation of tensor-product patches).
//
// Every other face (triangle, n-gon) is split into n quads around its
// centroid c, one per vertex v_i: (c, m_{i-1,i}, v_i, m_{i,i+1}) with m the
// edge midpoints. For a counter-clockwise face each quad is counter-clockwise
// too, so cross(dP/du, dP/dv) keeps pointing to the face's front, and for a
// planar convex face the quads tile it exactly. These are the quads the
// first Catmull-Clark step makes of a non-quad face (there with the vertex at
// (0,0)), so flat and subdivided versions of a mesh split faces alike.
#include <type_traits>
#include <vector>

#include "subdiv/patch_buffer.h"
#include "subdiv/patch_emit.h"

namespace mp {
namespace {

using subdiv_detail::DevicePatch;

DevicePatch bilinear_patch(const glm::dvec3& p00, const glm::dvec3& p10, const glm::dvec3& p11,
                           const glm::dvec3& p01) {
  DevicePatch patch;
  for (int j = 0; j < 4; ++j) {
    double v = j / 3.0;
    for (int i = 0; i < 4; ++i) {
      double u = i / 3.0;
      patch[4 * j + i] = (1 - u) * (1 - v) * p00 + u * (1 - v) * p10 + u * v * p11 + (1 - u) * v * p01;
    }
  }
  subdiv_detail::set_bezier_partners(patch);
  return patch;
}

}  // namespace

void append_polygon_patches(const Mesh& mesh, const glm::mat4& to_space, PatchBuffer& out) {
  subdiv_detail::check_face_topology(mesh);
  const subdiv_detail::PatchInfoCommon common =
      subdiv_detail::make_patch_info_common(to_space, mesh.double_sided);

  const int layers = out.uv_layers;
  std::vector<glm::dvec3> corners;
  std::vector<glm::dvec2> uvs;                       // [layer * n + corner]
  std::vector<glm::vec2> patch_uvs(size_t(4 * layers));  // append_device_patch's layout
  const bool smooth = !mesh.corner_normals.empty();
  std::vector<glm::dvec3> normals;                   // the face's corner normals, when smooth
  size_t first = 0;
  for (size_t face = 0; face < mesh.face_vertex_counts.size(); ++face) {
    const int n = mesh.face_vertex_counts[face];
    corners.clear();
    uvs.assign(size_t(n * layers), glm::dvec2(0.0));
    normals.clear();
    for (int k = 0; k < n; ++k) {
      corners.emplace_back(mesh.points[mesh.face_vertex_indices[first + k]]);
      if (smooth) normals.emplace_back(mesh.corner_normals[first + k]);
      for (int l = 0; l < layers; ++l) uvs[size_t(l * n + k)] = glm::dvec2(subdiv_detail::corner_uv(mesh, l, first + k));
    }
    first += size_t(n);
    const int material = subdiv_detail::face_material(mesh, face);

    if (n == 4) {
      for (size_t i = 0; i < uvs.size(); ++i) patch_uvs[i] = glm::vec2(uvs[i]);
      subdiv_detail::append_device_patch(bilinear_patch(corners[0], corners[1], corners[2], corners[3]),
                                         MP_PATCH_BEZIER, material, int(face), common, out, patch_uvs.data(),
                                         smooth ? normals.data() : nullptr);
      continue;
    }
    // The split quads carry the same bilinear blend of the face's UVs and
    // normals as of its points: centroid, edge midpoints, corner.
    auto quad = [n](const auto* v, int k, auto* out4) {
      std::decay_t<decltype(v[0])> centroid(0.0);
      for (int i = 0; i < n; ++i) centroid += v[i];
      centroid /= double(n);
      const auto& prev = v[(k + n - 1) % n];
      const auto& next = v[(k + 1) % n];
      out4[0] = centroid, out4[1] = 0.5 * (prev + v[k]), out4[2] = v[k], out4[3] = 0.5 * (v[k] + next);
    };
    for (int k = 0; k < n; ++k) {
      glm::dvec3 q[4];
      quad(corners.data(), k, q);
      for (int l = 0; l < layers; ++l) {
        glm::dvec2 t[4];
        quad(uvs.data() + l * n, k, t);
        for (int c = 0; c < 4; ++c) patch_uvs[size_t(4 * l + c)] = glm::vec2(t[c]);
      }
      glm::dvec3 qn[4];
      if (smooth) quad(normals.data(), k, qn);
      subdiv_detail::append_device_patch(bilinear_patch(q[0], q[1], q[2], q[3]), MP_PATCH_BEZIER, material,
                                         int(face), common, out, patch_uvs.data(), smooth ? qn : nullptr);
    }
  }
}

}  // namespace mp
