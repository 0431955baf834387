// The trees bound & split opens instances down (patch_tree.h): every patch
// below the root once, every node's box around its children's, balanced.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pipeline/device_scene/patch_tree.h"

namespace mp {
namespace {

struct Walk {
  const std::vector<DevicePatchNode>& nodes;
  const std::vector<glm::vec3>& boxes;
  uint32_t first;
  std::vector<int> seen;
  int depth = 0;

  // The box of `ref`'s subtree, checked against its node's.
  void visit(uint32_t ref, int level, glm::vec3* lo, glm::vec3* hi) {
    if (!MP_IS_NODE(ref)) {
      ASSERT_GE(ref, first);
      ASSERT_LT(ref - first, seen.size());
      ++seen[ref - first];
      *lo = boxes[2 * (ref - first)], *hi = boxes[2 * (ref - first) + 1];
      depth = std::max(depth, level);
      return;
    }
    ASSERT_LT(MP_NODE_INDEX(ref), nodes.size());
    const DevicePatchNode n = nodes[MP_NODE_INDEX(ref)];
    glm::vec3 l0, h0, l1, h1;
    visit(n.child[0], level + 1, &l0, &h0);
    visit(n.child[1], level + 1, &l1, &h1);
    *lo = glm::min(l0, l1), *hi = glm::max(h0, h1);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(n.lo[k], (*lo)[k]);  // exactly the children's: no slack, none missing
      EXPECT_EQ(n.hi[k], (*hi)[k]);
    }
  }
};

TEST(PatchTree, HoldsEveryPatchOnceInBalancedBoxes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> at(-10.0f, 10.0f), size(0.0f, 0.5f);
  for (uint32_t count : {1u, 2u, 3u, 17u, 1000u}) {
    std::vector<glm::vec3> boxes;
    for (uint32_t p = 0; p < count; ++p) {
      const glm::vec3 c(at(rng), at(rng), at(rng)), h(size(rng), size(rng), size(rng));
      boxes.push_back(c - h), boxes.push_back(c + h);
    }
    std::vector<DevicePatchNode> nodes(5);  // another surface's tree before this one
    const uint32_t first = 40;
    const PatchTree t = build_patch_tree(boxes, first, nodes);
    EXPECT_EQ(nodes.size(), 5 + count - 1);
    Walk w{nodes, boxes, first, std::vector<int>(count, 0)};
    glm::vec3 lo, hi;
    w.visit(t.root, 0, &lo, &hi);
    for (uint32_t p = 0; p < count; ++p) EXPECT_EQ(w.seen[p], 1) << "patch " << p << " of " << count;
    EXPECT_EQ(w.depth, t.depth);
    EXPECT_EQ(t.depth, int(std::ceil(std::log2(double(count)))));  // median splits
    if (count == 1) EXPECT_EQ(t.root, first);                       // a lone patch is its own root
  }
}

TEST(PatchTree, SplitsAlongTheLongestAxis) {
  // Four patches in a row along y: the root's children hold the two lower
  // and the two upper, not a mix.
  std::vector<glm::vec3> boxes;
  for (int k = 0; k < 4; ++k) boxes.push_back({0.0f, float(3 - k), 0.0f}), boxes.push_back({0.1f, float(3 - k) + 0.1f, 0.1f});
  std::vector<DevicePatchNode> nodes;
  const PatchTree t = build_patch_tree(boxes, 0, nodes);
  const DevicePatchNode& root = nodes[MP_NODE_INDEX(t.root)];
  const DevicePatchNode& a = nodes[MP_NODE_INDEX(root.child[0])];
  const DevicePatchNode& b = nodes[MP_NODE_INDEX(root.child[1])];
  EXPECT_LE(a.hi[1], b.lo[1]);
  EXPECT_FLOAT_EQ(a.hi[1] - a.lo[1], 1.1f);
}

}  // namespace
}  // namespace mp
