// A prototype surface's tree of patches (DevicePatchNode, kernels/core/
// mp_types.h): bound & split opens an instance down it, so a view drops what
// it cannot see a subtree at a time instead of patch by patch
// (kernels/geometry/mp_instance.h).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/mp_types.h"

namespace mp {

struct PatchTree {
  uint32_t root = 0;  // MP_NODE_REF(node), or the one patch of a surface of one patch
  int depth = 0;      // nodes on the longest path from the root to a patch
};

// Builds the tree over patches [first, first + boxes.size() / 2), whose
// boxes (2 per patch: lo, hi) are given in order, appending its nodes to
// `nodes`. Median splits along the longest axis of the patches' centres: a
// balanced tree, depth ceil(log2 n), whose subtrees are compact in space.
PatchTree build_patch_tree(const std::vector<glm::vec3>& boxes, uint32_t first, std::vector<DevicePatchNode>& nodes);

}  // namespace mp
