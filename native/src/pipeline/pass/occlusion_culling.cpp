#include "pipeline/pass/occlusion_culling.h"

#include <algorithm>
#include <limits>
#include <numeric>

#include "cl/kernel_args.h"
#include "geometry/mp_bound.h"

namespace mp {
namespace {

// Level-0 cells are 4 x 4 pixels: diced sub-patches span a few pixels to a
// few tens, and the test reads up to 4 x 4 cells of the level that fits.
constexpr int kCellShift = 2;

}  // namespace

OcclusionCulling::OcclusionCulling(DeviceSession& session)
    : session_(session),
      base_(session.program(), "occlusion_base"),
      reduce_(session.program(), "occlusion_reduce"),
      covered_(session.allocate(sizeof(cl_uint), "covered pixel count")) {}

OcclusionParams occlusion_layout(const FrameParams& f, int cell_shift) {
  OcclusionParams o{};
  o.cell_shift = cell_shift;
  o.base_w = std::max((f.width + (1 << cell_shift) - 1) >> cell_shift, 1);
  o.base_h = std::max((f.height + (1 << cell_shift) - 1) >> cell_shift, 1);
  o.levels = 1;
  while (o.levels < MP_OCCLUSION_MAX_LEVELS && std::max(o.base_w, o.base_h) > (1 << (o.levels - 1))) ++o.levels;
  return o;
}

void OcclusionCulling::size_for(const FrameParams& f) {
  const OcclusionParams o = occlusion_layout(f, kCellShift);
  params_ = o;
  size_t cells = 0;
  for (int k = 0; k < o.levels; ++k)
    cells += size_t((o.base_w + (1 << k) - 1) >> k) * size_t((o.base_h + (1 << k) - 1) >> k);
  if (cells > cells_held_) {
    pyramid_ = dirty_ = cl::Buffer();
    pyramid_ = session_.allocate(cells * sizeof(cl_uint), "occlusion pyramid");
    dirty_ = session_.allocate(cells, "occlusion cells");
    cells_held_ = cells;
  }
  cells_ = cells;
}

void OcclusionCulling::begin_frame(const FrameParams& f, StageTimer& timer) {
  size_for(f);
  const size_t cells = cells_;
  cl::Event e, e2;
  session_.queue().enqueueFillBuffer(pyramid_, ~cl_uint(0), 0, cells * sizeof(cl_uint), nullptr, &e);
  session_.queue().enqueueFillBuffer(dirty_, cl_uchar(0), 0, size_t(params_.base_w) * size_t(params_.base_h), nullptr,
                                     &e2);
  timer.add(Stage::Occlusion, e);
  timer.add(Stage::Occlusion, e2);
}

void OcclusionCulling::build_base(const cl::Buffer& keys, const FrameParams& f, bool all, StageTimer& timer,
                                  const cl_int4& count_region) {
  DeviceQueue& q = session_.queue();
  q.enqueueFillBuffer(covered_, cl_uint(0), 0, sizeof(cl_uint));
  bind_args(base_, keys, f, params_, pyramid_, dirty_, cl_int(all ? 1 : 0), covered_, count_region);
  cl::Event e;
  q.enqueueNDRangeKernel(base_, cl::NullRange, range_2d(params_.base_w, params_.base_h), cl::NDRange(8, 8), nullptr,
                         &e);
  timer.add(Stage::Occlusion, e);
}

void OcclusionCulling::refresh(const cl::Buffer& keys, const FrameParams& f, StageTimer& timer) {
  build_base(keys, f, false, timer, cl_int4{{0, 0, f.width, f.height}});
  for (int k = 1; k < params_.levels; ++k) {
    bind_args(reduce_, pyramid_, params_, k);
    cl::Event e;
    session_.queue().enqueueNDRangeKernel(
        reduce_, cl::NullRange, range_2d((params_.base_w + (1 << k) - 1) >> k, (params_.base_h + (1 << k) - 1) >> k),
        cl::NDRange(8, 8), nullptr, &e);
    timer.add(Stage::Occlusion, e);
  }
}

size_t OcclusionCulling::covered_pixels(const cl::Buffer& keys, const FrameParams& f, StageTimer& timer,
                                        const Bucket& b) {
  size_for(f);
  build_base(keys, f, true, timer, cl_int4{{b.x0 - b.sx0, b.y0 - b.sy0, b.x1 - b.sx0, b.y1 - b.sy0}});
  cl_uint n = 0;
  session_.queue().enqueueReadBuffer(covered_, CL_TRUE, 0, sizeof n, &n);
  return n;
}

const cl::Buffer& OcclusionCulling::root_order(const std::vector<glm::vec4>& boxes,
                                               const std::vector<glm::vec4>& instances, uint64_t scene_key,
                                               const FrameParams& f) {
  uint64_t key = scene_key;
  for (const float v : {f.ax, f.bx, f.ay, f.by, f.clip_near, f.clip_far, float(f.width), float(f.height)})
    key = (key ^ uint64_t(as_uint(v))) * 0x100000001b3ull;
  if (order_() && key == order_key_) return order_;
  const std::vector<cl_uint> order = near_to_far_order(boxes, f, &overlap_, instances);
  order_ = cl::Buffer();
  order_ = session_.allocate(std::max<size_t>(order.size(), 1) * sizeof(cl_uint), "occlusion patch order",
                             CL_MEM_READ_ONLY);
  if (!order.empty())
    session_.queue().enqueueWriteBuffer(order_, CL_TRUE, 0, order.size() * sizeof(cl_uint), order.data());
  order_key_ = key;
  return order_;
}

std::vector<cl_uint> near_to_far_order(const std::vector<glm::vec4>& boxes, const FrameParams& f, double* overlap,
                                       const std::vector<glm::vec4>& instances) {
  // The distance from the eye (camera space's origin) to box p: not its
  // depth, which would put the sides of every shell around the camera
  // (boxes that reach behind the eye) before the nearest one's front. Boxes
  // the kernels will cull as outside the view (mp_bound.h) go last.
  const size_t patch_count = boxes.size() / 2;
  std::vector<float> near(patch_count);
  // Boxes counted over a coarse grid of the frame.
  constexpr int kGrid = 64;
  std::vector<uint32_t> count(kGrid * kGrid, 0);
  const float sx = float(kGrid) / float(std::max(f.width, 1)), sy = float(kGrid) / float(std::max(f.height, 1));
  // Counts a box over the grid (weight times); false where the view culls it.
  auto counted = [&](glm::vec3 lo, glm::vec3 hi, uint32_t weight) {
    const MpBound b = mp_bound_boxes(&lo, &hi, 1, f);
    if (mp_bound_culled(b, &lo, &hi, 1, f, nullptr, 1)) return false;
    int x0 = 0, x1 = kGrid - 1, y0 = 0, y1 = kGrid - 1;  // reaching behind the eye: may cover the frame
    if (f.ortho || b.dmin > f.eye_epsilon) {
      x0 = std::clamp(int(b.xmin * sx), 0, kGrid - 1), x1 = std::clamp(int(b.xmax * sx), 0, kGrid - 1);
      y0 = std::clamp(int(b.ymin * sy), 0, kGrid - 1), y1 = std::clamp(int(b.ymax * sy), 0, kGrid - 1);
    }
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) count[y * kGrid + x] += weight;
    return true;
  };
  for (size_t p = 0; p < patch_count; ++p) {
    const glm::vec3 lo(boxes[2 * p]), hi(boxes[2 * p + 1]);
    near[p] = counted(lo, hi, 1) ? glm::length(glm::clamp(glm::vec3(0.0f), lo, hi))
                                 : std::numeric_limits<float>::infinity();
  }
  for (size_t i = 0; i + 1 < instances.size(); i += 2) counted(glm::vec3(instances[i]), glm::vec3(instances[i + 1]), 2);
  size_t sum = 0, covered = 0;
  for (uint32_t c : count) sum += c, covered += c > 0;
  if (overlap) *overlap = covered ? double(sum) / double(covered) : 0.0;
  std::vector<cl_uint> order(patch_count);
  std::iota(order.begin(), order.end(), cl_uint(0));
  std::stable_sort(order.begin(), order.end(), [&](cl_uint a, cl_uint b) { return near[a] < near[b]; });
  return order;
}

std::vector<cl_uint> view_near_to_far_order(const std::vector<glm::vec4>& boxes, const FrameParams& v) {
  const size_t patch_count = boxes.size() / 2;
  glm::mat3 r(1.0f);  // rows of the rotation, camera space -> view space
  glm::vec3 t(0.0f);
  if (v.has_view)
    for (int i = 0; i < 3; ++i)
      r[i] = glm::vec3(v.view[4 * i], v.view[4 * i + 1], v.view[4 * i + 2]), t[i] = v.view[4 * i + 3];
  // The eye in camera space: -R^T t.
  const glm::vec3 eye = -(r[0] * t[0] + r[1] * t[1] + r[2] * t[2]);
  std::vector<std::pair<float, cl_uint>> near(patch_count);
  for (size_t p = 0; p < patch_count; ++p) {
    const glm::vec3 lo(boxes[2 * p]), hi(boxes[2 * p + 1]);
    float d;
    if (v.ortho) {
      float z = t[2];  // the box's largest view-space z: its nearest depth is -z
      for (int i = 0; i < 3; ++i) z += std::max(r[2][i] * lo[i], r[2][i] * hi[i]);
      d = -z;
    } else {
      d = glm::length(glm::clamp(eye, lo, hi) - eye);
    }
    near[p] = {d, cl_uint(p)};
  }
  std::sort(near.begin(), near.end());
  std::vector<cl_uint> order(patch_count);
  for (size_t p = 0; p < patch_count; ++p) order[p] = near[p].second;
  return order;
}

}  // namespace mp
