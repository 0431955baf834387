// Bicubic Bezier patch sets: the 16 control points already are the device
// net (cp[4*j + i], u fastest); the partners repeat the interior points.
#include <cmath>
#include <string>

#include "subdiv/patch_buffer.h"
#include "subdiv/patch_emit.h"

namespace mp {

void append_bezier_patches(const BezierPatches& set, const glm::mat4& to_space, PatchBuffer& out) {
  const size_t count = set.control_points.size() / 16;
  if (count * 16 != set.control_points.size())
    throw Error("bezier patches '" + set.name + "': " + std::to_string(set.control_points.size()) +
                " control points is not a multiple of 16");
  if (set.material < 0) throw Error("bezier patches '" + set.name + "': negative material index");
  for (const glm::vec3& p : set.control_points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error("bezier patches '" + set.name + "': a control point is not finite");

  subdiv_detail::PatchInfoCommon common = subdiv_detail::make_patch_info_common(to_space, set.double_sided);
  if (set.round_u) common.flags |= MP_PATCH_ROUND_U;
  out.points.reserve(out.points.size() + count * MP_PATCH_POINTS);
  out.info.reserve(out.info.size() + count);
  for (size_t patch_index = 0; patch_index < count; ++patch_index) {
    subdiv_detail::DevicePatch patch;
    for (int k = 0; k < 16; ++k) patch[k] = glm::dvec3(set.control_points[16 * patch_index + k]);
    subdiv_detail::set_bezier_partners(patch);
    subdiv_detail::append_device_patch(patch, MP_PATCH_BEZIER, set.material, int(patch_index), common,
                                       out);
  }
}

}  // namespace mp
