// A Blender 4.x Principled BSDF at its defaults (Base Color 0.8, Roughness
// 0.5, IOR 1.5, no coat, sheen, transmission or film), seen head-on, for
// host tests of kernels/closures/mp_principled.h to change what they test.
#pragma once

#include "core/mp_compat.h"
#include "closures/mp_principled.h"

inline MpPrincipled principled_defaults() {
  MpPrincipled p{};
  p.base_color = MP_F3(0.8f, 0.8f, 0.8f);
  p.roughness = 0.5f;
  p.ior = 1.5f;
  p.alpha = 1.0f;
  p.specular = 0.5f;
  p.specular_tint = MP_F3(1.0f, 1.0f, 1.0f);
  p.coat_ior = 1.5f;
  p.coat_tint = p.sheen_tint = MP_F3(1.0f, 1.0f, 1.0f);
  p.nv = p.coat_nv = 1.0f;
  p.v4 = 1;
  p.retro = 0;
  p.diffuse_roughness = 0.0f;
  return p;
}
