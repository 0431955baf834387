// Shadow maps on the device (kernels/mp_shadow.h, kernels/shadow.cl). Each
// frame, before the camera's view:
//  1. the lights' layout (shadow_layout.h) and records go to the device;
//  2. a coarse pass over the camera's view (bound & split, dicing and
//     displacement) marks the pages its vertices need, at the levels their
//     pixel footprints ask for (soft shadows: their blocker search's);
//  3. the requests come back and get physical pages within the budget
//     (shadow_page_pool.h); pages kept from earlier frames whose light and
//     geometry did not change are not rendered again;
//  4. the lights' views go through bound & split, dicing and displacement
//     as the camera's do, several views per pass, and their micropolygons
//     are rasterised into the new pages (depth only);
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
#include "micropoly/renderer.h"
#include "pipeline/bound_split.h"
#include "pipeline/frame_params.h"
#include "pipeline/material_programs.h"
#include "pipeline/micropolygon_stages.h"
#include "pipeline/scene_buffers.h"
#include "pipeline/shadow_layout.h"
#include "pipeline/shadow_page_pool.h"
#include "pipeline/stage_timer.h"

namespace mp {

// Runs bound & split over the scene in `frame` (its own view, or `views`),
// handing the batches of diceable sub-patches to `sink`.
using BoundSplitRunner =
    std::function<BoundSplitResult(const FrameParams& frame, const PassViews& views, const DiceSink& sink)>;

// The stages a shadow pass shares with the camera's.
struct ShadowPassStages {
  GridLayoutStage& layout;
  DiceStage& dice;
  MaterialPrograms& programs;
  GridBuffers& grids;
};

class ShadowMaps {
 public:
  explicit ShadowMaps(DeviceSession& session);
  // Makes the frame's shadow maps (none when no light casts shadows);
  // returns false when the runner was cancelled.
  bool render(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame, const SceneBuffers& buffers, const ShadowPassStages& stages,
              const BoundSplitRunner& run, StageTimer& timer, ShadowStats& stats);
  const ShadowInputs& inputs() const { return inputs_; }

 private:
  // Marks the pages the camera's receivers need (the first marking), its
  // vertices kept for the soft marking where `keep`; returns them all,
  // coarser maps first, with their page-table entries.
  bool mark(const ShadowLayout& layout, const FrameSetup& frame, const SceneBuffers& buffers,
            const ShadowPassStages& stages, const BoundSplitRunner& run, StageTimer& timer, bool keep,
            std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats);
  // The soft marking, over the first's kept vertices; adds to its requests.
  void mark_soft(const ShadowLayout& layout, const FrameSetup& frame, StageTimer& timer,
                 std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries, ShadowStats& stats);
  void collect_requests(const ShadowLayout& layout, std::vector<ShadowPageKey>& keys, std::vector<uint32_t>& entries);
  void keep_room(size_t vertices);
  // Zeroes the page tables (`entries` of them) and writes the given entries.
  void write_table(size_t entries, const std::vector<cl_uint2>& writes);
  // Gives the requested pages physical ones, writes the page tables and
  // renders the new pages.
  bool allocate_and_render(const ShadowLayout& layout, const std::vector<ShadowPageKey>& keys,
                           const std::vector<uint32_t>& entries, const FrameSetup& frame, const SceneBuffers& buffers,
                           const ShadowPassStages& stages, const BoundSplitRunner& run, StageTimer& timer,
                           ShadowStats& stats);
  void upload_records(const ShadowLayout& layout);
  bool render_views(const std::vector<FrameParams>& views, const std::vector<uint8_t>& masks, const FrameSetup& frame,
                    const SceneBuffers& buffers, const ShadowPassStages& stages, const BoundSplitRunner& run,
                    StageTimer& timer, ShadowStats& stats);
  void ensure_pool(uint32_t pages);

  DeviceSession& session_;
  cl::Kernel mark_, mark_soft_, clear_, set_entries_, sample_;
  std::vector<size_t> light_pages_;  // resident pages per light, this frame
  ShadowPagePool pool_;
  ShadowInputs inputs_;
  cl::Buffer requests_, views_, masks_, clear_list_, writes_;
  cl::Buffer kept_p_, kept_n_;  // the first marking's vertices and normals, for the soft one
  size_t kept_capacity_ = 0, writes_capacity_ = 0;
  cl_uint kept_vertices_ = 0;
  size_t requests_capacity_ = 0, pages_capacity_ = 0, views_capacity_ = 0, masks_capacity_ = 0, clear_capacity_ = 0, records_capacity_ = 0,
         levels_capacity_ = 0;
  uint32_t pool_pages_ = 0;  // pages the pool buffer holds
};

}  // namespace mp
