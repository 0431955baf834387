// Host-side patch buffers: every surface type is turned into device patches
// (layout in kernels/geometry/mp_patch.h) by one of the append_* builders below.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "micropoly/scene.h"

namespace mp {

struct PatchBuffer {
  std::vector<glm::vec4> points;  // MP_PATCH_POINTS per patch, already transformed
  std::vector<glm::uvec4> info;   // PatchInfo per patch (type, material, flags, prim id)
  std::vector<uint32_t> edges;    // MP_EDGE_REFS curve references per patch (kernels/geometry/mp_patch.h)
  std::vector<glm::vec4> curves;  // MP_CURVE_FLOAT4S float4 per shared edge curve
  // UV maps: uv_layers x 2 float4 per patch, the corner UVs of each layer
  // (MP_PATCH_UV_* in kernels/geometry/mp_patch.h). Set uv_layers before appending.
  int uv_layers = 0;
  std::vector<glm::vec4> uvs;
  // Smooth shading normals at the patch's corners (0,0), (1,0), (1,1), (0,1),
  // 4 per patch (MP_PATCH_NORMALS in kernels/geometry/mp_patch.h); zero for patches
  // shaded with their own surface normal.
  std::vector<glm::vec4> normals;
  size_t size() const { return info.size(); }
};

// Catmull-Clark meshes: exact limit surface through OpenSubdiv Far adaptive
// refinement (regular B-spline patches converted to Bezier; Gregory-basis end caps).
void append_subdiv_patches(const Mesh& mesh, const glm::mat4& to_space, PatchBuffer& out);
// Polygon meshes: quads as bilinear patches, other faces split into quads
// around their centroid.
void append_polygon_patches(const Mesh& mesh, const glm::mat4& to_space, PatchBuffer& out);
// Bezier patch sets (RIB Patch/PatchMesh after basis conversion).
void append_bezier_patches(const BezierPatches& set, const glm::mat4& to_space, PatchBuffer& out);

// A ribbon patch's (MP_PATCH_CURVE) partners: the corners of a box around
// the strip in any orientation, from its points as they are placed (run
// again after any transform of them).
void bound_ribbon(glm::vec4* cp);

// Fills `edges` (and `curves`) for patches [first, size()): edges that two
// patches share, within a tolerance, get one curve and bit-identical corner
// points; an edge whose other side is two half-length edges (a transition
// between refinement levels, or a quad next to a split n-gon) refers to their
// two curves. Every other edge gets a curve of its own.
void share_patch_edges(PatchBuffer& buffer, size_t first);

}  // namespace mp
