#include "pipeline/frame/buckets.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "micropoly/error.h"

namespace mp {

std::vector<Bucket> plan_buckets(int width, int height, int spp, int reach, size_t max_samples) {
  auto fits = [&](int bw, int bh) {
    // The largest sample region of a bw x bh bucket: both margins inside the frame.
    const size_t w = size_t(std::min(width, bw + 2 * reach)), h = size_t(std::min(height, bh + 2 * reach));
    return w * h * size_t(spp) <= max_samples;
  };
  int nx = 1, ny = 1;
  if (!fits(width, height)) {
    if (!fits(16, 16))
      throw Error("the sample memory budget holds " + std::to_string(max_samples) +
                  " samples, fewer than a 16 x 16-pixel bucket at " + std::to_string(spp) +
                  " samples per pixel needs: raise the sample memory or lower the samples");
    // The side of a square bucket whose sample region fits, then the grid
    // of buckets of about that side over the frame.
    const int side = std::max(16, int(std::sqrt(double(max_samples) / spp)) - 2 * reach);
    nx = (width + side - 1) / side, ny = (height + side - 1) / side;
    while (!fits((width + nx - 1) / nx, (height + ny - 1) / ny)) {
      if ((width + nx - 1) / nx >= (height + ny - 1) / ny) ++nx;
      else ++ny;
    }
  }
  std::vector<Bucket> buckets;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      Bucket b;
      b.x0 = int(int64_t(width) * i / nx), b.x1 = int(int64_t(width) * (i + 1) / nx);
      b.y0 = int(int64_t(height) * j / ny), b.y1 = int(int64_t(height) * (j + 1) / ny);
      b.sx0 = std::max(0, b.x0 - reach), b.sx1 = std::min(width, b.x1 + reach);
      b.sy0 = std::max(0, b.y0 - reach), b.sy1 = std::min(height, b.y1 + reach);
      buckets.push_back(b);
    }
  return buckets;
}

FrameParams bucket_frame(const FrameParams& f, const Bucket& b) {
  FrameParams fb = f;
  fb.bx -= float(b.sx0);
  fb.by -= float(b.sy0);
  fb.bucket_x0 = f.bucket_x0 + b.sx0;
  fb.bucket_y0 = f.bucket_y0 + b.sy0;
  fb.crop_x0 += b.sx0;
  fb.crop_y0 += b.sy0;
  fb.width = b.sx1 - b.sx0;
  fb.height = b.sy1 - b.sy0;
  return fb;
}

}  // namespace mp
