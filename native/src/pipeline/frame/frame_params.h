// Per-frame constants derived from the Scene's camera and settings.
#pragma once

#include <glm/glm.hpp>

#include "micropoly/scene.h"
#include "core/mp_types.h"

namespace mp {

struct FrameSetup {
  FrameParams params{};
  int full_width = 0, full_height = 0;  // whole image; params.width/height is the crop
  int crop_x0 = 0, crop_y0 = 0;         // crop origin in the whole image (top-left)
  glm::mat3 camera_to_world{1.0f};
  // The camera's samples go through the binned sampler where a bin's keys
  // fit the device's local memory (SampleStage::begin_frame).
  bool bin_sampler = false;
};

// Screen window, raster mapping (RenderMan's conventions: the shorter side of
// the image spans [-1, 1] unless the scene sets a screen window), crop window,
// sampling and dicing limits.
FrameSetup make_frame_setup(const Scene& scene);

}  // namespace mp
