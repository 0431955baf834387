/* Occlusion culling of sub-patches against a hierarchical max-depth buffer
 * (Greene, Kass & Miller 1993; the hider of RenderMan culls primitives whose
 * bound lies behind its bucket's z-buffer before dicing them; Nanite's HZB).
 *
 * The pyramid is built from the sample buffer itself (occlusion.cl): a cell
 * holds the farthest depth any of its samples has so far, and an empty
 * sample counts as infinitely far. A sub-patch whose nearest depth (its
 * bound's, displacement included) lies beyond that depth in every cell its
 * raster bound touches can win no sample there: each sample keeps the
 * nearest depth it has seen, and depths only decrease. So culling never
 * changes the image, whatever the surfaces: a semi-transparent surface
 * writes only the samples its stochastic coverage keeps (the others stay as
 * they were), and a holdout hides what it hides in the image too. */
#ifndef MP_OCCLUSION_H
#define MP_OCCLUSION_H

#include "mp_compat.h"
#include "mp_types.h"

/* Cells per side of level `level` of a pyramid whose level 0 has `n`. */
MP_INLINE int mp_occlusion_side(int n, int level) { return (n + (1 << level) - 1) >> level; }

/* First cell of level `level`. */
MP_INLINE uint mp_occlusion_offset(OcclusionParams o, int level) {
  uint offset = 0u;
  for (int k = 0; k < level; ++k)
    offset += (uint)(mp_occlusion_side(o.base_w, k) * mp_occlusion_side(o.base_h, k));
  return offset;
}

/* Cells of all levels. */
MP_INLINE uint mp_occlusion_cells(OcclusionParams o) { return mp_occlusion_offset(o, o.levels); }

/* Whether what lies in the raster rectangle [xmin, xmax] x [ymin, ymax] at
 * depths from dmin on is hidden at every sample. The rectangle is read at the
 * level where it spans at most four cells per axis; a pixel of margin covers
 * the difference between the bound's arithmetic and the rasteriser's. */
MP_INLINE int mp_occluded(const MP_GLOBAL uint* pyramid, OcclusionParams o, FrameParams f, float xmin, float ymin,
                          float xmax, float ymax, float dmin) {
  if (o.levels <= 0 || !(dmin > 0.0f)) return 0;
  float wx = (float)(f.width - 1), wy = (float)(f.height - 1);
  int x0 = (int)clamp(xmin - 1.0f, 0.0f, wx) >> o.cell_shift, x1 = (int)clamp(xmax + 1.0f, 0.0f, wx) >> o.cell_shift;
  int y0 = (int)clamp(ymin - 1.0f, 0.0f, wy) >> o.cell_shift, y1 = (int)clamp(ymax + 1.0f, 0.0f, wy) >> o.cell_shift;
  int k = 0;
  while (k + 1 < o.levels && ((x1 >> k) - (x0 >> k) > 3 || (y1 >> k) - (y0 >> k) > 3)) ++k;
  uint offset = mp_occlusion_offset(o, k);
  int side = mp_occlusion_side(o.base_w, k);
  /* Depths of samples are positive floats, whose bits order as the floats;
   * a relative margin of 2^-16 covers rounding between bound and raster. */
  uint near_bits = as_uint(dmin * (1.0f - 1.0f / 65536.0f));
  for (int y = y0 >> k; y <= y1 >> k; ++y)
    for (int x = x0 >> k; x <= x1 >> k; ++x)
      if (pyramid[offset + (uint)(y * side + x)] >= near_bits) return 0;
  return 1;
}

#endif
