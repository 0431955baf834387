/* Exclusive prefix sum over uint arrays, used to compact the breadth-first
 * bound & split queue (Patney & Owens 2008; Blelloch 1990). Each work-group
 * scans MP_SCAN_BLOCK elements in local memory and writes its total; the host
 * scans the totals recursively and adds them back. */
#include "core/mp_compat.h"

#define MP_SCAN_GROUP 256
#define MP_SCAN_BLOCK (2 * MP_SCAN_GROUP)

__kernel __attribute__((reqd_work_group_size(MP_SCAN_GROUP, 1, 1)))
void scan_blocks(__global uint* data, uint n, __global uint* block_sums) {
  __local uint tmp[MP_SCAN_BLOCK];
  uint lid = get_local_id(0);
  uint base = get_group_id(0) * MP_SCAN_BLOCK;
  uint i0 = base + 2 * lid, i1 = i0 + 1;
  tmp[2 * lid] = i0 < n ? data[i0] : 0u;
  tmp[2 * lid + 1] = i1 < n ? data[i1] : 0u;
  /* Up-sweep. */
  uint offset = 1;
  for (uint d = MP_SCAN_BLOCK >> 1; d > 0; d >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid < d) {
      uint a = offset * (2 * lid + 1) - 1, b = offset * (2 * lid + 2) - 1;
      tmp[b] += tmp[a];
    }
    offset <<= 1;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid == 0) {
    block_sums[get_group_id(0)] = tmp[MP_SCAN_BLOCK - 1];
    tmp[MP_SCAN_BLOCK - 1] = 0u;
  }
  /* Down-sweep. */
  for (uint d = 1; d < MP_SCAN_BLOCK; d <<= 1) {
    offset >>= 1;
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid < d) {
      uint a = offset * (2 * lid + 1) - 1, b = offset * (2 * lid + 2) - 1;
      uint t = tmp[a];
      tmp[a] = tmp[b];
      tmp[b] += t;
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (i0 < n) data[i0] = tmp[2 * lid];
  if (i1 < n) data[i1] = tmp[2 * lid + 1];
}

__kernel void scan_add_block_offsets(__global uint* data, uint n, __global const uint* block_offsets) {
  uint i = get_global_id(0);
  if (i < n) data[i] += block_offsets[i / MP_SCAN_BLOCK];
}
