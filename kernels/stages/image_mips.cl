/* The MIP levels of the scene's images (textures/mp_tex_image.h), built on
 * the device after each upload of the scene data, level from level. */
#include "core/mp_compat.h"
#include "core/mp_types.h"
#include "textures/mp_tex_image.h"

/* Every texel of level `to` from level `from`, the level above it (the
 * image itself: level 0), in `levels`: the texel buffer being uploaded, not
 * yet the scene's (so not named as the scene's data, mp_scene_data.h). */
__kernel void reduce_image_level(__global float4* levels, DeviceImage from, DeviceImage to, uint from_image) {
  uint i = get_global_id(0);
  if (i >= to.width * to.height) return;
  uint x = i % to.width, y = i / to.width;
  levels[(ulong)to.offset + i] = from_image ? mp_image_first_level_texel(levels, from, to, x, y)
                                            : mp_image_reduce_texel(levels, from, to, x, y);
}
