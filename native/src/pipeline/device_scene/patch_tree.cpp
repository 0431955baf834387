#include "pipeline/device_scene/patch_tree.h"

#include <algorithm>
#include <numeric>

#include "micropoly/error.h"

namespace mp {
namespace {

struct Builder {
  const std::vector<glm::vec3>& boxes;
  uint32_t first;
  std::vector<DevicePatchNode>& nodes;
  std::vector<uint32_t> order;
  int depth = 0;

  glm::vec3 centre(uint32_t p) const { return 0.5f * (boxes[2 * p] + boxes[2 * p + 1]); }

  // The subtree over order[a, b) (b - a >= 1), `level` nodes above it.
  uint32_t build(size_t a, size_t b, int level) {
    if (b - a == 1) {
      depth = std::max(depth, level);
      return first + order[a];
    }
    const size_t index = nodes.size();
    nodes.emplace_back();
    glm::vec3 lo(3e38f), hi(-3e38f), clo(3e38f), chi(-3e38f);
    for (size_t k = a; k < b; ++k) {
      const uint32_t p = order[k];
      lo = glm::min(lo, boxes[2 * p]), hi = glm::max(hi, boxes[2 * p + 1]);
      clo = glm::min(clo, centre(p)), chi = glm::max(chi, centre(p));
    }
    const glm::vec3 extent = chi - clo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const size_t mid = a + (b - a) / 2;
    std::nth_element(order.begin() + long(a), order.begin() + long(mid), order.begin() + long(b),
                     [&](uint32_t x, uint32_t y) { return centre(x)[axis] < centre(y)[axis]; });
    const uint32_t left = build(a, mid, level + 1), right = build(mid, b, level + 1);
    DevicePatchNode& n = nodes[index];  // after the recursion: `nodes` may have moved
    for (int k = 0; k < 3; ++k) n.lo[k] = lo[k], n.hi[k] = hi[k];
    n.child[0] = left, n.child[1] = right;
    return MP_NODE_REF(index);
  }
};

}  // namespace

PatchTree build_patch_tree(const std::vector<glm::vec3>& boxes, uint32_t first, std::vector<DevicePatchNode>& nodes) {
  const size_t count = boxes.size() / 2;
  if (count == 0) throw Error("a prototype surface without patches has no tree");
  if (uint64_t(first) + count > MP_NODE_BIT || nodes.size() + count > MP_NODE_BIT)
    throw Error("the scene's patches exceed the 2^31 that instances' trees can name");
  Builder b{boxes, first, nodes, std::vector<uint32_t>(count)};
  std::iota(b.order.begin(), b.order.end(), 0u);
  PatchTree t;
  t.root = b.build(0, count, 0);
  t.depth = b.depth;
  return t;
}

}  // namespace mp
