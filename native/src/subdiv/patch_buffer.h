// Host-side patch buffers: every surface type is turned into device patches
// (layout in kernels/mp_patch.h) by one of the append_* builders below.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "micropoly/scene.h"

namespace mp {

struct PatchBuffer {
  std::vector<glm::vec4> points;  // MP_PATCH_POINTS per patch, already transformed
  std::vector<glm::uvec4> info;   // PatchInfo per patch (type, material, flags, prim id)
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

}  // namespace mp
