// Bicubic Bezier patch sets: the 16 control points already are the device
// net (cp[4*j + i], u fastest); the partners repeat the interior points.
#include <algorithm>
#include <cmath>
#include <string>

#include "subdiv/patch_buffer.h"
#include "subdiv/patch_emit.h"

namespace mp {
// A ribbon's partners (mp_patch.h, MP_PATCH_CURVE): the corners of a box
// around the strip in any orientation, from its placed points: each centre
// control point grown by its radius, since the curve lies in the hull of
// its control points and the radius in that of its values. The radius is
// the largest of the three offsets, at least their mean, which is what the
// kernels take (mp_ribbon.h), and sqrt 2 of it: in a light's view the strip
// also moves a radius away from the light.
void bound_ribbon(glm::vec4* cp) {
  glm::vec3 lo(0.0f), hi(0.0f);
  for (int j = 0; j < 4; ++j) {
    const glm::vec3 c(cp[4 * j]);
    float r = 0.0f;
    for (int k = 1; k <= 3; ++k) r = std::max(r, glm::length(glm::vec3(cp[4 * j + k]) - c));
    r *= 1.41422f;
    const glm::vec3 a = c - glm::vec3(r), b = c + glm::vec3(r);
    lo = j == 0 ? a : glm::min(lo, a);
    hi = j == 0 ? b : glm::max(hi, b);
  }
  for (int k = 0; k < 4; ++k) {
    const glm::vec3 corner = (k & 1) ? hi : lo;
    cp[16 + k] = glm::vec4(corner, cp[16 + k].w);
  }
}


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
  for (const auto& layer : set.uv_layers)
    if (layer.size() != 4 * count)
      throw Error("bezier patches '" + set.name + "': a UV layer has " + std::to_string(layer.size()) +
                  " values; it needs 4 per patch");
  // The set's corner UVs of each layer the buffer holds (zeros past its own).
  std::vector<glm::vec2> corners(4 * size_t(std::max(out.uv_layers, 0)));
  for (size_t patch_index = 0; patch_index < count; ++patch_index) {
    subdiv_detail::DevicePatch patch;
    for (int k = 0; k < 16; ++k) patch[k] = glm::dvec3(set.control_points[16 * patch_index + k]);
    subdiv_detail::set_bezier_partners(patch);
    for (size_t k = 0; k < corners.size(); ++k)
      corners[k] = k / 4 < set.uv_layers.size() ? set.uv_layers[k / 4][4 * patch_index + k % 4] : glm::vec2(0.0f);
    subdiv_detail::append_device_patch(patch, set.ribbons ? MP_PATCH_CURVE : MP_PATCH_BEZIER, set.material,
                                       int(patch_index), common, out, set.uv_layers.empty() ? nullptr : corners.data());
    if (set.ribbons) bound_ribbon(&out.points[out.points.size() - MP_PATCH_POINTS]);
  }
}

}  // namespace mp
