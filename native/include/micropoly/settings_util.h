#pragma once
#include "micropoly/scene.h"

namespace mp {
// Splits N samples per pixel into a stratification grid as close to square
// as N allows (16 -> 4x4, 8 -> 2x4, 7 -> 1x7).
inline void set_samples_per_pixel(RenderSettings& s, int n) {
  if (n < 1) n = 1;
  int sx = 1;
  for (int d = 1; d * d <= n; ++d)
    if (n % d == 0) sx = d;
  s.samples_x = sx;
  s.samples_y = n / sx;
}
}  // namespace mp
