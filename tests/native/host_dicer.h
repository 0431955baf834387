// Bound & split and dicing run on the host through the same headers the
// kernels compile (mp_bound.h, mp_surface.h): the reference for tests that
// inspect every diced grid.
#pragma once

#include <algorithm>
#include <array>
#include <functional>
#include <vector>

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_grid.h"
#include "geometry/mp_bound.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/device_scene/scene_buffers.h"

namespace mp::test {

struct DicedGrid {
  SubPatch sp;
  MpGridShape shape;
  std::vector<glm::vec3> p;                   // the grid's vertices
  std::vector<glm::vec2> uv;                  // the patch parameters of p
  std::vector<glm::vec3> slot_p;              // positions by slot (mp_grid.h)
  std::vector<std::array<uint, 4>> polygons;  // micropolygons, as slots
};

// Calls `visit` for every grid the pipeline would dice for `scene`, with the
// frame and the scene's device patches.
inline void host_dice(const Scene& scene,
                      const std::function<void(const DicedGrid&, const FrameParams&, const PatchBuffer&)>& visit) {
  FrameParams f = make_frame_setup(scene).params;
  f.samples = MP_SAMPLES_UNKNOWN;  // every grid, sampled or not
  HostSceneData data = prepare_scene_data(scene);
  const PatchBuffer& pb = data.patches;
  const uint* info = reinterpret_cast<const uint*>(pb.info.data());
  std::vector<SubPatch> stack;
  // The patches placed on their own (this dicer places no instances).
  for (uint p = 0; p < data.own_patches; ++p) stack.push_back(SubPatch{{0, 0, 1, 0, 1, 1, 0, 1}, p, 0, 0, MP_NO_INSTANCE});
  const MpPlacement none = mp_placement_none();
  DicedGrid g;
  while (!stack.empty()) {
    SubPatch sp = stack.back();
    stack.pop_back();
    const uint d = mp_classify(pb.points.data(), info, pb.edges.data(), pb.curves.data(), nullptr, nullptr, nullptr, &sp, f,
                               nullptr, nullptr, OcclusionParams{});
    const uint action = MP_DECISION_ACTION(d);
    if (action >= MP_SPLIT_U) {
      SubPatch a, b;
      mp_split(&sp, action, &a, &b);
      stack.push_back(b);
      stack.push_back(a);
      continue;
    }
    if (action != MP_DICE) continue;
    g.sp = sp;
    g.sp.info = MP_DICED_INFO(sp.info, d);
    g.shape = mp_grid_shape(&g.sp, uint(f.max_grid));
    const uint stride = uint(f.max_grid) + 1;
    g.p.clear();
    g.uv.clear();
    g.slot_p.assign(size_t(stride) * stride, glm::vec3(NAN));
    for (uint j = 0; j < stride; ++j)
      for (uint i = 0; i < stride; ++i) {
        glm::vec2 uv;
        if (!mp_slot_uv(&g.sp, &g.shape, i, j, &uv)) continue;
        float3 P, du, dv;
        mp_surface_point(pb.points.data(), info, pb.edges.data(), pb.curves.data(), sp.patch, uv.x, uv.y, &none, &P, &du,
                         &dv);
        g.p.push_back(P);
        g.uv.push_back(uv);
        g.slot_p[mp_slot(&g.shape, i, j)] = P;
      }
    g.polygons.clear();
    std::array<uint, 4> q;
    for (uint m = 0; mp_grid_micropolygon(&g.shape, m, q.data()); ++m) g.polygons.push_back(q);
    visit(g, f, pb);
  }
}

}  // namespace mp::test
