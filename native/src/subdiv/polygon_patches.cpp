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

  std::vector<glm::dvec3> corners;
  size_t first = 0;
  for (size_t face = 0; face < mesh.face_vertex_counts.size(); ++face) {
    const int n = mesh.face_vertex_counts[face];
    corners.clear();
    for (int k = 0; k < n; ++k) corners.emplace_back(mesh.points[mesh.face_vertex_indices[first + k]]);
    first += size_t(n);
    const int material = subdiv_detail::face_material(mesh, face);

    if (n == 4) {
      subdiv_detail::append_device_patch(bilinear_patch(corners[0], corners[1], corners[2], corners[3]),
                                         MP_PATCH_BEZIER, material, int(face), common, out);
      continue;
    }
    glm::dvec3 centroid(0.0);
    for (const glm::dvec3& c : corners) centroid += c;
    centroid /= double(n);
    for (int k = 0; k < n; ++k) {
      const glm::dvec3& prev = corners[(k + n - 1) % n];
      const glm::dvec3& next = corners[(k + 1) % n];
      const glm::dvec3& here = corners[k];
      subdiv_detail::append_device_patch(
          bilinear_patch(centroid, 0.5 * (prev + here), here, 0.5 * (here + next)), MP_PATCH_BEZIER,
          material, int(face), common, out);
    }
  }
}

}  // namespace mp
