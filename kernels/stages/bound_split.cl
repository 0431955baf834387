/* Bound & split, in two strategies that make the same decisions (mp_bound.h)
 * and therefore reach the same set of diceable sub-patches:
 *
 *  - breadth-first (Patney & Owens 2008): every iteration classifies the whole
 *    queue, then prefix sums compact the diceable sub-patches and the split
 *    children into new arrays. Memory grows with the widest level.
 *  - bounded (Weber, Wimmer & Owens 2015): a fixed pool of workers, each
 *    processing sub-patches depth-first from a stack of its own; split
 *    children are handed to idle workers through a small ring buffer. Memory
 *    is fixed by the number of workers and the stack depth. */
#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_grid.h"
#include "geometry/mp_bound.h"
#include "core/mp_scene_data.h"

/* Root r of a pass over root_count roots (mp_instance.h) in one or more
 * views: the whole domain of root r % root_count in view r / root_count, no
 * edge rated yet. With an order of the patch_count patches placed on their
 * own (occlusion culling), those are taken in it, near to far, and then the
 * instances' roots (the host sorts instances near to far); a pass over
 * several views (one light's shadow maps) takes each root in all its views
 * before the next, so every view's pyramid fills with the nearest surfaces
 * first. */
#define MP_ROOT_SUBPATCH(r, view_count, order) \
  mp_root_subpatch((r), patch_count, root_count, instances, (view_count), (order))

inline SubPatch mp_root_subpatch(uint r, uint patch_count, uint root_count, __global const DeviceInstance* instances,
                                 uint view_count, __global const uint* order) {
  uint views = max(view_count, 1u);
  uint q, view;
  if (!order) {
    q = r % root_count, view = r / root_count;
  } else if (r < patch_count * views) {
    q = order[r / views], view = r % views;
  } else {
    q = patch_count + (r - patch_count * views) / views, view = r % views;
  }
  SubPatch sp;
  uint patch, instance;
  mp_root_patch(q, patch_count, instances, &patch, &instance);
  mp_whole_subpatch(patch, instance, view << 24, &sp);
  return sp;
}

/* ---- breadth-first ------------------------------------------------------ */

/* Initial queue: one whole-domain sub-patch per patch and view. */
__kernel void bs_init_queue(MP_SCENE_PARAMS __global SubPatch* queue, uint n, uint view_count,
                            __global const uint* order) {
  uint i = get_global_id(0);
  if (i >= n) return;
  queue[i] = MP_ROOT_SUBPATCH(i, view_count, order);
}

__kernel void bs_breadth_classify(MP_SCENE_PARAMS __global SubPatch* queue, uint n, FrameParams f,
                                  __global const FrameParams* views, uint view_count,
                                  __global const uchar* page_masks, __global const uint* occlusion,
                                  OcclusionParams occ, volatile __global uint* occluded, __global uint* decision,
                                  __global uint* dice_flag, __global uint* split_flag) {
  uint i = get_global_id(0);
  if (i > n) return;
  if (i == n) { /* a zero past the end, so the exclusive scans end in the totals */
    dice_flag[n] = 0u;
    split_flag[n] = 0u;
    return;
  }
  SubPatch sp = queue[i];
  uint d = mp_classify(points, patch_info, patch_edges, edge_curves, patch_bounds, instances, patch_nodes, &sp,
                       mp_subpatch_view(&sp, f, views, view_count), page_masks, occlusion, occ);
  uint action = MP_DECISION_ACTION(d);
  if (d == MP_CULL_OCCLUDED) atomic_inc(occluded);
  queue[i] = sp; /* with the edge rates measured here */
  decision[i] = d;
  dice_flag[i] = action == MP_DICE ? 1u : 0u;
  split_flag[i] = action >= MP_SPLIT_U ? 1u : 0u;
}

/* After the exclusive scans: dice_flag holds dice offsets, split_flag split offsets. */
__kernel void bs_breadth_scatter(__global const SubPatch* queue, uint n, __global const uint* decision,
                                 __global const uint* dice_offset, __global const uint* split_offset,
                                 __global SubPatch* next_queue, __global SubPatch* diceable) {
  uint i = get_global_id(0);
  if (i >= n) return;
  uint d = decision[i];
  uint action = MP_DECISION_ACTION(d);
  SubPatch sp = queue[i];
  if (action == MP_DICE) {
    sp.info = MP_DICED_INFO(sp.info, d);
    diceable[dice_offset[i]] = sp;
  } else if (action >= MP_SPLIT_U) {
    SubPatch a, b;
    mp_split(&sp, action, &a, &b);
    next_queue[2 * split_offset[i]] = a;
    next_queue[2 * split_offset[i] + 1] = b;
  }
}

/* ---- bounded memory -------------------------------------------------------- */

/* Counters shared by all workers (one small buffer). */
#define BS_POOL_HEAD 0   /* next ring index to take */
#define BS_POOL_TAIL 1   /* next ring index to write */
#define BS_NEXT_ROOT 2   /* next input root (patch and view) to take */
#define BS_DICE_COUNT 3  /* diceable sub-patches written */
#define BS_BUSY 4        /* workers left with work after this launch */
#define BS_IDLE 5        /* workers that ran out of work in this launch */
#define BS_MAX_BUSY 6    /* 1 + highest index of a worker left with work */
#define BS_OCCLUDED 7    /* sub-patches culled by occlusion */
/* What the host sets for each launch, read-only during it (so the
 * kernel's arguments stay bound from one launch to the next): */
#define BS_RING_HEAD0 8  /* the ring's head and tail as the launch starts */
#define BS_RING_TAIL0 9
#define BS_DONATE 10     /* children a launch may hand out (its idle workers) */
#define BS_ROOT_LIMIT 11 /* the roots taken so far (occlusion culling takes them in waves) */
#define BS_ACTIVE 12     /* workers that run: those below it (a chained launch covers a fixed range) */
/* Chained launches (bs_bounded_control): */
#define BS_OCCLUDED_SUM 13 /* BS_OCCLUDED summed over the chain's launches */
#define BS_STOP 14         /* set where the host must decide: the batch is full or the roots taken are done */
#define BS_STEPS 15        /* launches of the chain that ran before it stopped */
#define BS_COUNTERS 16

__kernel void bs_bounded_step(MP_SCENE_PARAMS __global const uint* root_order, FrameParams f,
                              __global const FrameParams* views, uint view_count, __global const uchar* page_masks,
                              __global const uint* occlusion, OcclusionParams occ,
                              __global SubPatch* stacks, __global uint* stack_sizes, uint stack_depth,
                              __global SubPatch* ring, uint ring_capacity,
                              __global SubPatch* diceable, uint dice_capacity,
                              volatile __global uint* counters, uint steps) {
  uint w = get_global_id(0);
  if (counters[BS_STOP] != 0u || w >= counters[BS_ACTIVE]) return;
  const uint ring_head0 = counters[BS_RING_HEAD0], ring_tail0 = counters[BS_RING_TAIL0];
  const uint donate_limit = counters[BS_DONATE], root_limit = counters[BS_ROOT_LIMIT];
  __global SubPatch* stack = stacks + (ulong)w * stack_depth;
  uint size = stack_sizes[w];
  for (uint step = 0; step < steps; ++step) {
    /* Once this batch of diceable sub-patches is full, stop before doing work
     * that would only be repeated after the flush. */
    if (counters[BS_DICE_COUNT] >= dice_capacity) break;
    if (size == 0u) {
      /* Refill: first from work that others handed out, then from the input. */
      uint r = atomic_inc(&counters[BS_POOL_HEAD]);
      if (r < ring_tail0) {
        stack[size++] = ring[r % ring_capacity];
      } else {
        uint r = atomic_inc(&counters[BS_NEXT_ROOT]);
        if (r >= root_limit) break; /* the roots taken so far (occlusion culling takes them in waves) */
        stack[size++] = MP_ROOT_SUBPATCH(r, view_count, root_order);
      }
    }
    SubPatch sp = stack[--size];
    uint d = mp_classify(points, patch_info, patch_edges, edge_curves, patch_bounds, instances, patch_nodes, &sp,
                         mp_subpatch_view(&sp, f, views, view_count), page_masks, occlusion, occ);
    uint action = MP_DECISION_ACTION(d);
    if (d == MP_CULL_OCCLUDED) atomic_inc(&counters[BS_OCCLUDED]);
    if (action == MP_DICE) {
      uint slot = atomic_inc(&counters[BS_DICE_COUNT]);
      if (slot >= dice_capacity) {
        stack[size++] = sp; /* batch full: keep it for after the flush */
        break;
      }
      sp.info = MP_DICED_INFO(sp.info, d);
      diceable[slot] = sp;
    } else if (action >= MP_SPLIT_U) {
      SubPatch a, b;
      mp_split(&sp, action, &a, &b);
      int donated = 0;
      if (donate_limit > 0u) {
        /* Ring entries written now become visible to takers in the next launch
         * only, so takers never read a slot that is still being written. */
        uint t = atomic_inc(&counters[BS_POOL_TAIL]);
        if (t - ring_tail0 < donate_limit && t - ring_head0 < ring_capacity) {
          ring[t % ring_capacity] = b;
          donated = 1;
        }
      }
      if (!donated) stack[size++] = b;
      stack[size++] = a;
    }
  }
  stack_sizes[w] = size;
  atomic_inc(&counters[size > 0u ? BS_BUSY : BS_IDLE]);
  if (size > 0u) atomic_max(&counters[BS_MAX_BUSY], w + 1u);
}

/* Between two chained launches of bs_bounded_step, one work-item does what
 * the host does between two launches (bound_split_bounded.cpp): it takes
 * the launch's counters, and unless the dice batch is full or the roots
 * taken so far are all done (then it sets BS_STOP and leaves the counters
 * as the launch left them, for the host to read), it sets them for the
 * next launch: the ring's head and tail, the workers that run (those left
 * with work, plus room to double, within `useful` and whole work-groups of
 * 64, at most `workers`) and the children they may hand out. The host's
 * rules and these are the same, so a chain of launches splits exactly as
 * launches read back one by one. */
__kernel void bs_bounded_control(volatile __global uint* counters, uint ring_capacity, uint dice_capacity,
                                 uint workers, uint useful) {
  if (get_global_id(0) != 0u || counters[BS_STOP] != 0u) return;
  counters[BS_STEPS] += 1u;
  counters[BS_OCCLUDED_SUM] += counters[BS_OCCLUDED];
  const uint head0 = counters[BS_RING_HEAD0], tail0 = counters[BS_RING_TAIL0];
  const uint hungry0 = counters[BS_DONATE], root_limit = counters[BS_ROOT_LIMIT];
  uint head = min(counters[BS_POOL_HEAD], tail0);
  uint tail = min(min(counters[BS_POOL_TAIL], tail0 + hungry0), head0 + ring_capacity);
  const uint next_root = min(counters[BS_NEXT_ROOT], root_limit);
  const uint dice = min(counters[BS_DICE_COUNT], dice_capacity);
  const uint busy = counters[BS_BUSY];
  if (head == tail) head = tail = 0u;
  if (dice == dice_capacity || (busy == 0u && head == tail && next_root >= root_limit)) {
    counters[BS_STOP] = 1u;
    return;
  }
  const ulong pending = (ulong)(tail - head) + (ulong)(root_limit - next_root);
  const ulong wanted = max((ulong)counters[BS_MAX_BUSY], min(2ul * busy + pending, (ulong)useful));
  const uint launch = (uint)min((ulong)workers, max(64ul, (wanted + 63ul) / 64ul * 64ul));
  counters[BS_POOL_HEAD] = head;
  counters[BS_POOL_TAIL] = tail;
  counters[BS_NEXT_ROOT] = next_root;
  counters[BS_DICE_COUNT] = dice;
  counters[BS_BUSY] = 0u;
  counters[BS_IDLE] = 0u;
  counters[BS_MAX_BUSY] = 0u;
  counters[BS_OCCLUDED] = 0u;
  counters[BS_RING_HEAD0] = head;
  counters[BS_RING_TAIL0] = tail;
  counters[BS_DONATE] = launch > busy ? launch - busy : 0u;
  counters[BS_ACTIVE] = launch;
}
