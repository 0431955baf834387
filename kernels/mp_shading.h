/* Surface shading after RenderMan's standard shaders (RenderMan Interface
 * Specification 3.2, appendix A: constant, matte, plastic) and its light
 * shaders (ambientlight, distantlight, pointlight, spotlight). Camera space. */
#ifndef MP_SHADING_H
#define MP_SHADING_H

#include "mp_compat.h"
#include "mp_types.h"

MP_INLINE float mp_smoothstep(float e0, float e1, float x) {
  if (e1 <= e0) return x >= e1 ? 1.0f : 0.0f;
  float t = clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

/* Radiance-like color leaving point p with normal n towards the eye. */
MP_INLINE float3 mp_shade(float3 p, float3 n, int ortho, MP_GLOBAL const DeviceMaterial* m,
                          MP_GLOBAL const DeviceLight* lights, uint light_count) {
  float3 cs = MP_F3(m->color[0], m->color[1], m->color[2]);
  float3 emission = MP_F3(m->emission[0], m->emission[1], m->emission[2]);
  int model = (int)m->color[3];
  if (model == 0) return cs + emission;
  float3 v = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : normalize(-p);
  float3 nf = dot(n, v) < 0.0f ? -n : n; /* faceforward */
  float ka = m->coeffs[0], kd = m->coeffs[1], ks = m->coeffs[2];
  float inv_roughness = 1.0f / fmax(m->coeffs[3], 1e-4f);
  float3 ambient = MP_F3(0.0f, 0.0f, 0.0f), diffuse = ambient, specular = ambient;
  for (uint k = 0; k < light_count; ++k) {
    MP_GLOBAL const DeviceLight* lt = lights + k;
    float3 cl = MP_F3(lt->color[0], lt->color[1], lt->color[2]);
    int type = (int)lt->color[3];
    if (type == MP_LIGHT_AMBIENT) {
      ambient += cl;
      continue;
    }
    float3 l;
    if (type == MP_LIGHT_DISTANT) {
      l = -MP_F3(lt->direction[0], lt->direction[1], lt->direction[2]);
    } else {
      float3 to_light = MP_F3(lt->position[0], lt->position[1], lt->position[2]) - p;
      float d2 = fmax(dot(to_light, to_light), 1e-20f);
      l = to_light / sqrt(d2);
      float atten = 1.0f / d2;
      if (type == MP_LIGHT_SPOT) {
        float cosangle = -dot(l, MP_F3(lt->direction[0], lt->direction[1], lt->direction[2]));
        atten *= cosangle > 0.0f ? pow(cosangle, lt->cone[2]) : 0.0f;
        atten *= mp_smoothstep(lt->cone[0], lt->cone[1], cosangle);
      }
      cl *= atten;
    }
    float ndotl = dot(nf, l);
    if (ndotl <= 0.0f) continue;
    diffuse += cl * ndotl;
    float3 h = normalize(l + v);
    specular += cl * pow(fmax(dot(nf, h), 0.0f), inv_roughness);
  }
  float3 c = cs * (ka * ambient + kd * diffuse);
  if (model == 2) c += MP_F3(m->specular[0], m->specular[1], m->specular[2]) * (ks * specular);
  return c + emission;
}

#endif
