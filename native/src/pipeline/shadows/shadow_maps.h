// Shadow maps on the device (kernels/shadow/mp_shadow.h, kernels/stages/shadow.cl). Each
// frame, before the camera's view:
//  1. the lights' layout (shadow_layout.h) and records go to the device;
//  2. a coarse pass over the camera's view (bound & split, dicing and
//     displacement) writes the camera's coarse depth, culling what it hides
//     near to far (marking_depth.h), and keeps its vertices; those the
//     camera may see then mark the pages they need, at the levels their
//     pixel footprints ask for (soft shadows: their blocker search's);
//  3. the requests come back and get physical pages within the budget
//     (shadow_page_pool.h); pages kept from earlier frames whose light and
//     geometry did not change are not rendered again;
//  4. the lights' views go through bound & split, dicing and displacement
//     as the camera's do, several views per pass, and their micropolygons
//     are rasterised into the new pages (depth only); with culling, nothing
//     beyond a page's farthest receiver (its request) is diced;
//  5. for soft shadows, a second marking runs the first search round on
//     those maps, from the vertices the first marking kept (no second pass
//     over the scene): where it finds occluders, the finer levels the penumbra
//     filter reads there are marked, allocated and rendered as in 3 and 4
//     (a penumbra is wider than the pixels wherever its occluders stand
//     off the receiver, and needs no finer texels there).
// Shading then reads the maps through inputs().
#pragma once

#include <functional>
#include <vector>

#include "cl/device_session.h"
#include "cl/kernel_args.h"
#include "micropoly/renderer.h"
#include "pipeline/pass/bound_split.h"
#include "pipeline/frame/camera_view.h"
#include "pipeline/frame/frame_params.h"
#include "pipeline/materials/material_programs.h"
#include "pipeline/pass/micropolygon_pass.h"
#include "pipeline/pass/micropolygon_stages.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/shadows/marking_depth.h"
#include "pipeline/shadows/shadow_layout.h"
#include "pipeline/shadows/shadow_changes.h"
#include "pipeline/shadows/shadow_page_pool.h"
#include "pipeline/pass/stage_timer.h"

namespace mp {

class ShadowMaps {
 public:
  explicit ShadowMaps(DeviceSession& session);
  // Makes the frame's shadow maps (none when no light casts shadows);
  // returns false when the runner was cancelled. `camera_order`: the
  // patches near to far from the camera, where the camera's view may cull
  // (none: the marking neither culls nor tests what the camera sees).
  bool render(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame, MicropolygonPass& pass,
              const cl::Buffer& camera_order, ShadowStats& stats);
  const ShadowInputs& inputs() const { return inputs_; }
  // This frame's camera roots, those the marking's coarse depth may see
  // first (none where it had no depth).
  CameraRoots camera_roots();

 private:
  // render's work; where it is cancelled, render forgets the pages granted
  // for rendering this frame (pending_), which may hold nothing their keys name.
  bool render_maps(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame,
                   MicropolygonPass& pass, const cl::Buffer& camera_order, ShadowStats& stats);
  // Forgets the kept pages that a surface changed since the last frame may
  // reach (all of them where that cannot be told: shadow_changes.h), and
  // records this frame's surfaces for the next.
  void forget_changed_pages(const ShadowLayout& layout, const std::vector<Light>& lights, ShadowCasters casters);
  // The camera's coarse view: its depth (culling what it hides, where
  // `camera_order` is given) and its vertices, kept within their share of
  // the budget (with their normals where `soft`) for the markings; past
  // that share, batches mark their pages at once.
  bool camera_view(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass, bool soft,
                   const cl::Buffer& camera_order, ShadowStats& stats);
  // Marks the pages the camera's receivers need (the first marking) from
  // the kept vertices the camera may see, and, unless `first` (the camera
  // view marked them then), from the view diced again where they passed
  // their share; returns them all, coarser maps first, with their page-table
  // entries.
  bool mark(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass, bool first,
            std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats);
  // The soft marking, over the first's kept vertices (or, where they passed
  // their share of the budget, over the view diced again); adds to its
  // requests. Returns false when the runner was cancelled.
  bool mark_soft(const ShadowLayout& layout, const FrameSetup& frame, MicropolygonPass& pass,
                 std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats);
  // Dices the markings' coarse view again (culled by the camera's complete
  // coarse depth) and runs `kernel` on each batch's vertices, its arguments
  // bound by `bind`; false when the runner was cancelled.
  bool mark_again(MicropolygonPass& pass, const FrameParams& coarse, bool normals, cl::Kernel& kernel,
                  ShadowStats& stats, const std::function<void(const cl::Buffer&, cl_uint)>& bind);
  // A marking kernel over `items` vertices, timed as the marking.
  void launch(cl::Kernel& kernel, cl_uint items, StageTimer& timer);
  void collect_requests(const ShadowLayout& layout, std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries);
  void keep_room(size_t vertices);
  void clear_requests(const ShadowLayout& layout);
  // Zeroes the page tables (`entries` of them) and writes the given entries.
  void write_table(size_t entries, const std::vector<cl_uint2>& writes);
  // Gives the requested pages physical ones, writes the page tables and
  // renders the new pages.
  bool allocate_and_render(const ShadowLayout& layout, const std::vector<ShadowPageKey>& keys,
                           const std::vector<uint32_t>& entries, const FrameSetup& frame, MicropolygonPass& pass,
                           ShadowStats& stats, bool culling);
  void upload_records(const ShadowLayout& layout);
  // Renders the views (of light `lights[i]` each, in culling group
  // `groups[i]`) into their fresh pages, a pass per group where occlusion
  // culling is on (`culling`).
  bool render_views(const std::vector<FrameParams>& views, const std::vector<int>& lights,
                    const std::vector<int>& groups,
                    const std::vector<uint8_t>& masks, const FrameSetup& frame, MicropolygonPass& pass,
                    ShadowStats& stats, bool culling, cl_uint fresh_pages);
  void ensure_pool(uint32_t pages);
  // The patches near to far from light `light`'s eye (or along a sun), kept
  // while the light and the scene's geometry stay; empty when the orders
  // would pass their share of the budget (the pass then culls at batch ends
  // only).
  const cl::Buffer& light_order(int light, const FrameParams& view, const SceneBuffers& buffers, uint64_t scene_key);
  // Vertices the camera's view may keep for the markings within the budget.
  size_t kept_limit_ = 0;
  bool kept_overflow_ = false;
  cl::Buffer camera_order_;  // this frame's (camera_view)
  size_t orders_limit_ = 0;  // bytes the lights' patch orders may hold

  DeviceSession& session_;
  cl::Kernel mark_, mark_kept_, mark_soft_, mark_soft_grid_, clear_, set_entries_, list_requests_, farthest_,
      occlusion_build_;
  SceneKernel sample_;
  std::vector<size_t> light_pages_;  // resident pages per light, this frame
  ShadowPagePool pool_;
  ShadowInputs inputs_;
  // Per page-table entry, whether it is asked for and its cap (the
  // farthest receiver's depth, mp_mark_rect); the device's list of those
  // asked for; the caps of the pages asked for, as collect_requests lists
  // them, and of the fresh pages (caps_list_, as clear_list_).
  cl::Buffer requests_, caps_, list_, views_, masks_, clear_list_, caps_list_, writes_;
  size_t caps_held_ = 0, list_held_ = 0;
  auto request_args() const { return arg_pack(requests_, caps_); }
  std::vector<uint32_t> request_caps_;
  bool capped_ = false;  // whether pages render only what lies in front of their caps
  cl::Buffer kept_p_, kept_n_;  // the camera view's vertices and (soft shadows) normals, for the markings
  size_t kept_capacity_ = 0, writes_capacity_ = 0, caps_capacity_ = 0;
  bool kept_normals_ = false;  // whether normals are kept too (kept_n_, as many as kept_p_)
  cl::Buffer list_count_;
  MarkingDepth depth_;
  cl_uint kept_vertices_ = 0;
  size_t requests_capacity_ = 0, pages_capacity_ = 0, views_capacity_ = 0, masks_capacity_ = 0, clear_capacity_ = 0, records_capacity_ = 0,
         levels_capacity_ = 0;
  uint32_t pool_pages_ = 0;  // pages the pool buffer holds
  // Occlusion culling of the lights' views (mp_occlusion.h): whether the
  // pass wrote to each pool page since the last look, and the views'
  // pyramids with the pages' cells (mp_page_occluded).
  cl::Buffer dirty_, pyramid_;
  size_t pyramid_capacity_ = 0;
  struct LightOrder {
    uint64_t key = 0;
    cl::Buffer order;
    size_t bytes = 0;
  };
  std::vector<LightOrder> orders_;
  uint64_t scene_key_ = 0;
  ShadowCasters casters_;  // the surfaces the pool's pages were rendered from
  std::vector<ShadowPageKey> pending_;
};

}  // namespace mp
