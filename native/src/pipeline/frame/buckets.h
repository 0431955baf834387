// Buckets: a frame whose samples would take more device memory than the
// budget (RenderSettings::sample_memory_mib) is rendered a rectangle at a
// time, as RenderMan's buckets and Cycles' tiles. Each bucket's samples
// cover its pixels plus the pixel filter's reach around them, so the filter
// sees every sample it would in the whole frame and the seams cannot be
// found; the sample patterns and stochastic opacity follow whole-image
// pixels (mp_raster.h, mp_sample.h), and a sub-patch is diced the same in
// every bucket that meets it (its rates do not depend on the bucket).
#pragma once

#include <cstddef>
#include <vector>

#include "core/mp_types.h"

namespace mp {

struct Bucket {
  int x0, y0, x1, y1;  // the pixels it resolves, [x0, x1) x [y0, y1), in the frame's pixels
  int sx0, sy0, sx1, sy1;  // the pixels it samples: the above plus the filter's reach, clipped to the frame
  size_t sample_pixels() const { return size_t(sx1 - sx0) * size_t(sy1 - sy0); }
};

// The fewest near-square buckets, in rows from the top, whose sample
// regions each hold at most `max_samples` samples of `spp` per pixel with a
// margin of `reach` pixels. One bucket (the whole frame) when it fits.
// Throws mp::Error when not even a 16 x 16-pixel bucket fits.
std::vector<Bucket> plan_buckets(int width, int height, int spp, int reach, size_t max_samples);

// The frame of bucket b's samples: frame f cropped to its sample region.
FrameParams bucket_frame(const FrameParams& f, const Bucket& b);

}  // namespace mp
