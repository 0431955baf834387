// OpenSubdiv's adaptive refinement of a Catmull-Clark mesh and the
// conversion of its patches into the device layout (kernels/geometry/mp_patch.h).
// append_subdiv_patches emits one device patch per Far patch, in patch table
// order (arrays, then patches), which is what the tests rely on to compare
// against OpenSubdiv's own evaluation of the same table.
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "micropoly/scene.h"
#include "subdiv/patch_emit.h"

namespace mp::subdiv_detail {

// Isolation depth around extraordinary vertices in smooth regions. Regular
// faces are exact bicubic patches at any depth; only the Gregory end caps
// around extraordinary vertices approximate the limit surface, and each level
// halves the parametric size of the region they cover.
constexpr int kSmoothIsolationLevel = 3;

struct SubdivRefinement {
  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner;
  std::unique_ptr<OpenSubdiv::Far::PatchTable> patch_table;  // null when the mesh has no faces
  // Base, refined and local (end cap) points in object space, indexed like the
  // patch table's control vertices.
  std::vector<glm::dvec3> points;
  // Base face of each ptex face (PatchParam::GetFaceId() is a ptex index).
  std::vector<int> ptex_to_face;
  // UV maps as OpenSubdiv face-varying channels (one per Mesh::uv_layers
  // entry, "linear all" interpolation): base and refined values per channel.
  std::vector<std::vector<glm::dvec2>> fvar;
  int isolation_level = 0;
};

// Deepest isolation the mesh needs: kSmoothIsolationLevel, raised to
// ceil(sharpness) of the sharpest semi-sharp crease or corner so that every
// semi-sharp feature has decayed to smooth before patches are built.
int subdiv_isolation_level(const Mesh& mesh);

// Throws mp::Error naming the mesh on invalid topology.
SubdivRefinement refine_subdiv_mesh(const Mesh& mesh);

// The device form of one Far patch (object space) and its MP_PATCH_* type.
unsigned convert_far_patch(const SubdivRefinement& refinement, int array, int patch,
                           DevicePatch& out);

// The UV of every layer at the corners (0,0), (1,0), (1,1), (0,1) of patch
// `absolute_patch` (array `array`), from OpenSubdiv's face-varying patches;
// `out` holds 4 per layer.
void far_patch_corner_uvs(const SubdivRefinement& refinement, int array, int absolute_patch,
                          glm::vec2* out);

}  // namespace mp::subdiv_detail
