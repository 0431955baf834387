#include "pipeline/frame/frame_params.h"

#include <algorithm>
#include <cmath>

namespace mp {

FrameSetup make_frame_setup(const Scene& scene) {
  const Camera& cam = scene.camera;
  const RenderSettings& s = scene.settings;
  FrameSetup out;
  FrameParams& f = out.params;
  out.full_width = s.width;
  out.full_height = s.height;

  float l = cam.screen_left, r = cam.screen_right, b = cam.screen_bottom, t = cam.screen_top;
  if (!(r > l) || !(t > b)) {
    float aspect = static_cast<float>(s.width) * s.pixel_aspect / static_cast<float>(s.height);
    if (aspect >= 1.0f) {
      l = -aspect, r = aspect, b = -1.0f, t = 1.0f;
    } else {
      l = -1.0f, r = 1.0f, b = -1.0f / aspect, t = 1.0f / aspect;
    }
  }
  bool ortho = cam.projection == Camera::Projection::Orthographic;
  float focal = ortho ? 1.0f : 1.0f / std::tan(0.5f * glm::radians(cam.fov_degrees));
  float w = static_cast<float>(s.width), h = static_cast<float>(s.height);

  // Crop window in whole pixels, as Blender's border render and RiCropWindow.
  out.crop_x0 = std::clamp(static_cast<int>(std::floor(s.crop_x0 * w)), 0, s.width - 1);
  out.crop_y0 = std::clamp(static_cast<int>(std::floor(s.crop_y0 * h)), 0, s.height - 1);
  int x1 = std::clamp(static_cast<int>(std::ceil(s.crop_x1 * w)), out.crop_x0 + 1, s.width);
  int y1 = std::clamp(static_cast<int>(std::ceil(s.crop_y1 * h)), out.crop_y0 + 1, s.height);

  f.ax = w * focal / (r - l);
  f.bx = -l * w / (r - l) - static_cast<float>(out.crop_x0);
  f.ay = -h * focal / (t - b);
  f.by = t * h / (t - b) - static_cast<float>(out.crop_y0);
  f.ortho = ortho ? 1 : 0;
  f.ndc_ax = focal / (r - l);
  f.ndc_bx = -l / (r - l);
  f.ndc_ay = focal / (t - b);
  f.ndc_by = -b / (t - b);
  f.width = x1 - out.crop_x0;
  f.height = y1 - out.crop_y0;
  f.spp_x = std::max(1, s.samples_x);
  f.spp_y = std::max(1, s.samples_y);
  f.clip_near = std::max(cam.clip_near, 0.0f);
  f.clip_far = cam.clip_far;
  f.micropoly_edge = std::sqrt(std::max(s.shading_rate, 1e-3f));
  f.texture_filter = s.texture_filter_width;
  f.samples = s.sample_culling ? MP_SAMPLES_PATTERN : MP_SAMPLES_UNKNOWN;
  // Edge rates are powers of two (mp_bound.h), so the grid limit is one too.
  f.max_grid = 1;
  while (f.max_grid * 2 <= std::clamp(s.max_grid_size, 1, MP_MAX_GRID)) f.max_grid *= 2;
  f.max_depth = std::clamp(s.max_split_depth, 1, 60);
  f.ribbon = 1.0f;
  // Bounds nearer than this are treated as crossing the eye plane. Anything
  // nearer than the near clip plane is clipped per sample anyway.
  f.eye_epsilon = std::max(0.5f * f.clip_near, 1e-6f);
  f.backface_culling = s.backface_culling ? 1 : 0;
  f.normal_pass = s.depth_and_normal_passes && s.normal_pass ? 1 : 0;
  f.seed = 0u;
  f.crop_x0 = out.crop_x0;
  f.crop_y0 = out.crop_y0;
  f.frame_bx = f.bx, f.frame_by = f.by;  // one bucket: the whole crop region
  f.bucket_x0 = f.bucket_y0 = 0;
  // A thin lens for perspective cameras (kernels/stages/mp_blur.h).
  const bool lens = !ortho && cam.lens_radius > 0.0f;
  f.lens_radius = lens ? cam.lens_radius : 0.0f;
  f.lens_x_scale = lens ? 1.0f / cam.aperture_ratio : 1.0f;
  f.focus_distance = lens ? cam.focus_distance : 1.0f;
  f.aperture_blades = lens && cam.aperture_blades >= 3 ? cam.aperture_blades : 0;
  f.aperture_rotation = lens ? cam.aperture_rotation : 0.0f;
  f.dof_dice_factor = s.dof_dice_factor;
  f.motion_steps = scene.motion_steps >= 2 ? scene.motion_steps : 0;
  out.camera_to_world = glm::transpose(glm::mat3(cam.world_to_camera));  // rotation part inverse
  return out;
}

}  // namespace mp
