// Bicubic patch bases (RI spec 3.2, RiBasis and RiPatchMesh) and their
// conversion to the bicubic Bezier nets the renderer consumes.
//
// RenderMan evaluates a bicubic patch as P(u,v) = U * Mu * G * Mv^T * V^T with
// U = [u^3 u^2 u 1], V likewise, and G[i][j] the control point i along u and
// j along v. With B the Bezier basis, the same surface has the Bezier net
// (B^-1 Mu) G (B^-1 Mv)^T; that change of basis is exact for every basis.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mp::rib {

using Mat4d = std::array<std::array<double, 4>, 4>;  // [row][column]

struct Basis {
  Mat4d matrix{};
  int step = 3;
};

// The named bases of the RI spec with their natural steps; false if unknown.
bool named_basis(const std::string& name, Basis* out);
Basis bezier_basis();
// From 16 numbers in row-major order, as written in a RIB array.
Mat4d basis_from_array(const std::vector<double>& values);

// C = B^-1 * M: maps a basis' geometry vector to Bezier control points.
Mat4d to_bezier_conversion(const Mat4d& basis);

// One bicubic patch: g[i + 4*j] is control point i along u, j along v.
// Writes the Bezier net in the same layout (cp[4*j + i]).
void bicubic_to_bezier(const glm::vec3 g[16], const Mat4d& cu, const Mat4d& cv, glm::vec3 out[16]);
// A bilinear patch (p[0]=P00, p[1]=P10, p[2]=P01, p[3]=P11), degree-elevated.
void bilinear_to_bezier(const glm::vec3 p[4], glm::vec3 out[16]);

// Number of patches along one direction of a PatchMesh, or -1 when the
// vertex count does not fit the basis step (RI spec: nonperiodic meshes need
// n = 4 + k*step vertices, periodic ones n = k*step; bilinear: n >= 2).
int64_t patches_along(bool bicubic, int n, bool periodic, int step);

// Expands a PatchMesh (points[u + nu*v], u fastest) into Bezier nets
// appended to `out` (16 points per patch). Counts must already be valid.
void patch_mesh_to_bezier(bool bicubic, int nu, bool uperiodic, int nv, bool vperiodic,
                          const Basis& ubasis, const Basis& vbasis,
                          const std::vector<glm::vec3>& points, std::vector<glm::vec3>& out);

}  // namespace mp::rib
