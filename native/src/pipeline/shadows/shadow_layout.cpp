#include "pipeline/shadows/shadow_layout.h"

#include <algorithm>
#include <cmath>

#include "shadow/mp_shadow.h"
#include "pipeline/device_scene/scene_fingerprint.h"

namespace mp {
namespace {

float max_scale(const glm::mat4& m) {
  return std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
}

void grow(WorldBounds& b, const std::vector<glm::vec3>& points, const glm::mat4& to_world, float pad) {
  if (points.empty()) return;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
  for (int k = 0; k < 8; ++k) {
    glm::vec3 c((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    glm::vec3 w = glm::vec3(to_world * glm::vec4(c, 1.0f));
    b.lo = glm::min(b.lo, w - glm::vec3(pad));
    b.hi = glm::max(b.hi, w + glm::vec3(pad));
  }
}

// How far displacement can move an object's surface, in world units.
float displacement_reach(const Scene& scene, int material, const std::vector<int>& face_materials,
                         const glm::mat4& to_world) {
  float reach = 0.0f;
  auto add = [&](int i) {
    if (i < 0 || size_t(i) >= scene.materials.size()) return;
    const Material& m = scene.materials[size_t(i)];
    if (m.program >= 0 && m.program_displaces)
      reach = std::max(reach, m.displacement_bound * (m.displacement_bound_world ? 1.0f : max_scale(to_world)));
  };
  add(material);
  for (int i : face_materials) add(i);
  return reach;
}

// Rows of a light's basis (x, y, z) in world space; the light looks down -z.
glm::dmat3 basis_looking(glm::dvec3 forward) {
  glm::dvec3 z = -glm::normalize(forward);
  glm::dvec3 ref = std::abs(z.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
  glm::dvec3 x = glm::normalize(glm::cross(ref, z));
  glm::dvec3 y = glm::cross(z, x);
  return glm::transpose(glm::dmat3(x, y, z));  // rows x, y, z
}

glm::dmat3 light_basis(const Light& l) {
  if (l.type == Light::Type::Point) return glm::dmat3(1.0);
  glm::dvec3 n = glm::dvec3(l.direction);
  if (!(glm::length(n) > 0.0)) n = glm::dvec3(0, 0, -1);
  if (l.type != Light::Type::Area) return basis_looking(n);
  n = glm::normalize(n);
  glm::dvec3 u = glm::dvec3(l.axis_u) - n * glm::dot(glm::dvec3(l.axis_u), n);
  if (!(glm::length(u) > 0.0)) return basis_looking(n);
  glm::dvec3 x = glm::normalize(u), z = -n, y = glm::cross(z, x);
  return glm::transpose(glm::dmat3(x, y, z));
}

// Row-major 3x4 (rows of m, translation t) into 12 floats.
void put_rows(float* out, const glm::dmat3& m, const glm::dvec3& t) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[4 * r + c] = float(m[c][r]);
    out[4 * r + 3] = float(t[r]);
  }
}

// A cube face's rotation (light space -> face view), from mp_cube_face_view.
glm::dmat3 face_rotation(int face) {
  glm::dmat3 m;
  for (int c = 0; c < 3; ++c) {
    float3 e(c == 0 ? 1.0f : 0.0f, c == 1 ? 1.0f : 0.0f, c == 2 ? 1.0f : 0.0f);
    m[c] = glm::dvec3(mp_cube_face_view(face, e));
  }
  return m;
}

FrameParams shadow_view_base(const FrameParams& camera, const RenderSettings& s) {
  FrameParams v = camera;
  v.has_view = 1;
  v.view_kind = MP_VIEW_SHADOW;
  v.samples = s.sample_culling ? MP_SAMPLES_CENTRES : MP_SAMPLES_UNKNOWN;
  v.micropoly_edge = std::sqrt(std::max(s.shadow_shading_rate, 1e-3f));
  v.ribbon = 1.0f;
  v.backface_culling = 0;
  v.normal_pass = 0;
  v.spp_x = v.spp_y = 1;
  v.crop_x0 = v.crop_y0 = 0;
  v.lens_radius = 0.0f;  // lights see through pinholes,
  v.motion_steps = 0;    // the shutter centre's scene
  return v;
}

}  // namespace

WorldBounds world_bounds(const Scene& scene) {
  WorldBounds b;
  for (const Mesh& m : scene.meshes)
    grow(b, m.points, m.object_to_world, displacement_reach(scene, m.material, m.face_materials, m.object_to_world));
  for (const BezierPatches& p : scene.bezier_patches)
    grow(b, p.control_points, p.object_to_world, displacement_reach(scene, p.material, {}, p.object_to_world));
  for (const WorldBounds& i : instance_bounds(scene))
    if (!i.empty()) b.lo = glm::min(b.lo, i.lo), b.hi = glm::max(b.hi, i.hi);
  return b;
}

namespace {

// A prototype surface's box in its own space and the displacement bounds
// of its per-face materials (object and world units).
struct SurfaceBox {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  glm::mat4 to_prototype{1.0f};
  int material = 0;
  float object_reach = 0.0f, world_reach = 0.0f;
};

void add_reach(const Scene& scene, int material, float& object_reach, float& world_reach) {
  if (material < 0 || size_t(material) >= scene.materials.size()) return;
  const Material& m = scene.materials[size_t(material)];
  if (m.program < 0 || !m.program_displaces) return;
  (m.displacement_bound_world ? world_reach : object_reach) =
      std::max(m.displacement_bound_world ? world_reach : object_reach, m.displacement_bound);
}

template <typename Surface>
SurfaceBox surface_box(const Scene& scene, const Surface& s, const std::vector<glm::vec3>& points,
                       const std::vector<int>& face_materials) {
  SurfaceBox b;
  for (const glm::vec3& p : points) b.lo = glm::min(b.lo, p), b.hi = glm::max(b.hi, p);
  b.to_prototype = s.object_to_world;
  b.material = s.material;
  for (int m : face_materials) add_reach(scene, m, b.object_reach, b.world_reach);
  return b;
}

}  // namespace

std::vector<WorldBounds> instance_bounds(const Scene& scene) {
  std::vector<std::vector<SurfaceBox>> boxes(scene.prototypes.size());
  for (size_t p = 0; p < scene.prototypes.size(); ++p) {
    for (const Mesh& m : scene.prototypes[p].meshes) boxes[p].push_back(surface_box(scene, m, m.points, m.face_materials));
    for (const BezierPatches& b : scene.prototypes[p].bezier_patches)
      boxes[p].push_back(surface_box(scene, b, b.control_points, {}));
  }
  std::vector<WorldBounds> out(scene.instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    auto place = [&](const glm::mat4& to_world) {
      for (const SurfaceBox& s : boxes[size_t(inst.prototype)]) {
        if (!(s.lo.x <= s.hi.x)) continue;
        float object_reach = s.object_reach, world_reach = s.world_reach;
        add_reach(scene, inst.material >= 0 ? inst.material : s.material, object_reach, world_reach);
        const glm::mat4 m = to_world * s.to_prototype;
        const float pad = std::max(object_reach * max_scale(m), world_reach);
        for (int k = 0; k < 8; ++k) {
          const glm::vec3 c((k & 1) ? s.hi.x : s.lo.x, (k & 2) ? s.hi.y : s.lo.y, (k & 4) ? s.hi.z : s.lo.z);
          const glm::vec3 w(m * glm::vec4(c, 1.0f));
          out[i].lo = glm::min(out[i].lo, w - glm::vec3(pad));
          out[i].hi = glm::max(out[i].hi, w + glm::vec3(pad));
        }
      }
    };
    place(inst.object_to_world);
    for (const glm::mat4& t : inst.motion_object_to_world) place(t);
  }
  return out;
}

WorldBounds surface_bounds(const Scene& scene, const Mesh& mesh) {
  WorldBounds b;
  const float reach = displacement_reach(scene, mesh.material, mesh.face_materials, mesh.object_to_world);
  grow(b, mesh.points, mesh.object_to_world, reach);
  for (const std::vector<glm::vec3>& step : mesh.motion_points) grow(b, step, mesh.object_to_world, reach);
  return b;
}

WorldBounds surface_bounds(const Scene& scene, const BezierPatches& set) {
  WorldBounds b;
  grow(b, set.control_points, set.object_to_world,
       displacement_reach(scene, set.material, {}, set.object_to_world));
  return b;
}

bool shadow_page_touches(const Light& light, int32_t map_id, int32_t x, int32_t y, const WorldBounds& box) {
  if (box.empty()) return false;
  // The box in the light's space (as the views' to_light rows place it).
  const glm::dmat3 basis = light_basis(light);
  const bool sun = light.type == Light::Type::Distant;
  const glm::dvec3 origin = sun ? glm::dvec3(0.0) : glm::dvec3(light.position);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 c((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
    const glm::dvec3 q = basis * (c - origin);
    lo = glm::min(lo, q), hi = glm::max(hi, q);
  }
  // Two texels of margin: the views reach light space through the camera's
  // in single precision, and a micropolygon on the box's edge covers the
  // texels whose centres it holds.
  constexpr double kMarginTexels = 2.0;
  double x0, y0, x1, y1;
  if (sun) {
    // A level's absolute page (x, y) holds light-space x in [x, x + 1) pages.
    const double texel = std::ldexp(1.0, map_id), page = texel * MP_PAGE_SIZE;
    x0 = (lo.x - kMarginTexels * texel) / page, x1 = (hi.x + kMarginTexels * texel) / page;
    y0 = (lo.y - kMarginTexels * texel) / page, y1 = (hi.y + kMarginTexels * texel) / page;
  } else {
    const int face = map_id / MP_CUBE_MIPS, mip = map_id % MP_CUBE_MIPS;
    float fx0, fy0, fx1, fy1;
    if (!mp_cube_face_box(face, glm::vec3(lo), glm::vec3(hi), float(mp_cube_mip_texels(mip)), &fx0,
                          &fy0, &fx1, &fy1))
      return false;
    x0 = (fx0 - kMarginTexels) / MP_PAGE_SIZE, x1 = (fx1 + kMarginTexels) / MP_PAGE_SIZE;
    y0 = (fy0 - kMarginTexels) / MP_PAGE_SIZE, y1 = (fy1 + kMarginTexels) / MP_PAGE_SIZE;
  }
  return x >= std::floor(x0) && x <= std::floor(x1) && y >= std::floor(y0) && y <= std::floor(y1);
}

void ShadowLayout::page_position(const ShadowMapInfo& m, int sx, int sy, int32_t* x, int32_t* y) const {
  *x = m.page_x + ((sx - m.origin_x) & (m.side - 1));
  *y = m.page_y + ((sy - m.origin_y) & (m.side - 1));
}

ShadowLayout make_shadow_layout(const Scene& scene, const std::vector<Light>& lights, const FrameSetup& frame,
                                const WorldBounds& bounds, uint64_t geometry_key) {
  ShadowLayout out;
  const RenderSettings& s = scene.settings;
  const FrameParams& f = frame.params;
  out.shadows.resize(lights.size());
  out.light_keys.assign(lights.size(), 0);
  out.own_bias.assign(lights.size(), 0);
  out.cull_group.resize(lights.size());
  for (size_t i = 0; i < lights.size(); ++i) out.cull_group[i] = lights[i].world_probe ? -1 : int(i);
  for (DeviceShadow& d : out.shadows) d = DeviceShadow{}, d.kind = MP_SHADOW_NONE, d.cone_cos = -2.0f;
  if (!s.shadows || bounds.empty()) return out;

  const glm::dmat4 c2w = glm::inverse(glm::dmat4(scene.camera.world_to_camera));
  const glm::dmat3 c2w_linear(c2w);
  const glm::dvec3 camera_position(c2w[3]);
  const glm::dvec3 lo(bounds.lo), hi(bounds.hi);
  const double diagonal = glm::length(hi - lo);
  auto corner = [&](int k) { return glm::dvec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z); };
  // Pixel footprints the scene's receivers can have: from its depth range in the camera.
  double dmin = 1e300, dmax = -1e300;
  for (int k = 0; k < 8; ++k) {
    double d = -(glm::dmat4(scene.camera.world_to_camera) * glm::dvec4(corner(k), 1.0)).z;
    dmin = std::min(dmin, d), dmax = std::max(dmax, d);
  }
  dmin = std::max(dmin, double(std::max(f.clip_near, 1e-6f)));
  dmax = std::clamp(dmax, dmin, double(f.clip_far));
  const float fp_lo = mp_pixel_footprint(float(dmin), f), fp_hi = mp_pixel_footprint(float(dmax), f);
  const FrameParams base = shadow_view_base(f, s);

  for (size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    if (!l.cast_shadows || l.type == Light::Type::Ambient) continue;
    if (l.type == Light::Type::Spot && !(l.cone_angle > 0.0f)) continue;
    DeviceShadow& d = out.shadows[i];
    const glm::dmat3 basis = light_basis(l);
    const glm::dmat3 r = basis * c2w_linear;
    const bool sun = l.type == Light::Type::Distant;
    const glm::dvec3 origin = sun ? glm::dvec3(0.0) : glm::dvec3(l.position);
    const glm::dvec3 t = basis * (camera_position - origin);
    put_rows(d.to_light, r, t);
    d.page_table = out.table_entries;
    // A world probe's shadow is as soft as a wide region of the sky: its
    // penumbrae span many texels of the level the footprint asks for, so
    // it is rendered two levels (16x fewer texels) coarser.
    out.own_bias[i] = l.world_probe ? kWorldProbeLevelBias : 0;
    d.level_bias = out.own_bias[i];
    d.cone_cos = l.type == Light::Type::Spot ? std::cos(std::clamp(l.cone_angle, 0.0f, 3.14159265f)) : -2.0f;
    d.one_sided = l.type == Light::Type::Area ? 1u : 0u;
    if (sun) {
      d.kind = MP_SHADOW_SUN;
      d.shape = l.angle > 0.0f ? MP_SHADOW_SHAPE_DISK : MP_SHADOW_SHAPE_POINT;
      d.size[0] = std::tan(0.5f * std::min(l.angle, 3.1f));
      // The scene in the light's space: depth counts down from its top.
      glm::dvec3 llo(1e300), lhi(-1e300);
      for (int k = 0; k < 8; ++k) {
        glm::dvec3 q = basis * corner(k);
        llo = glm::min(llo, q), lhi = glm::max(lhi, q);
      }
      const double margin = 1e-3 * diagonal + 1e-6;
      d.z_top = float(lhi.z + margin);
      const float depth_range = float(lhi.z - llo.z + 2.0 * margin);
      int l_lo = mp_sun_level_for(fp_lo), l_hi = mp_sun_level_for(fp_hi) + kMaxShadowLevelBias;
      if (d.shape != MP_SHADOW_SHAPE_POINT)
        l_hi = std::max(l_hi, mp_ceil_log2(std::max(d.size[0] * depth_range / MP_SHADOW_SEARCH_TEXELS, 1e-30f)));
      l_lo = std::max(l_lo, l_hi - (MP_MAX_SUN_LEVELS - 1));
      d.level0 = l_lo;
      d.levels = uint32_t(l_hi - l_lo + 1);
      d.level_records = uint32_t(out.levels.size());
      const glm::dvec2 camera_light(t.x, t.y);
      for (int lv = l_lo; lv <= l_hi; ++lv) {
        const double texel = std::ldexp(1.0, lv), page = texel * MP_PAGE_SIZE;
        const int32_t ax = int32_t(std::floor(camera_light.x / page)) - MP_MAP_PAGES / 2;
        const int32_t ay = int32_t(std::floor(camera_light.y / page)) - MP_MAP_PAGES / 2;
        DeviceShadowLevel rec{};
        rec.offset[0] = float(-ax * page);
        rec.offset[1] = float(-ay * page);
        rec.texel = float(texel);
        rec.page_table = out.table_entries;
        rec.origin_x = ax & (MP_MAP_PAGES - 1);
        rec.origin_y = ay & (MP_MAP_PAGES - 1);
        out.levels.push_back(rec);
        ShadowMapInfo m;
        m.light = int(i);
        m.map_id = lv;
        m.table = out.table_entries;
        m.side = MP_MAP_PAGES;
        m.origin_x = rec.origin_x, m.origin_y = rec.origin_y;
        m.page_x = ax, m.page_y = ay;
        m.coarseness = lv - l_lo;
        FrameParams& v = m.view = base;
        put_rows(v.view, r, glm::dvec3(t.x - ax * page, t.y - ay * page, t.z - double(d.z_top)));
        v.ortho = 1;
        v.ax = v.ay = float(1.0 / texel);
        v.bx = v.by = 0.0f;
        v.width = v.height = MP_MAP_TEXELS;
        v.clip_near = 0.0f;
        v.clip_far = depth_range;
        v.page_table = m.table;
        v.page_side = m.side;
        v.page_origin_x = m.origin_x, v.page_origin_y = m.origin_y;
        out.maps.push_back(m);
        out.table_entries += uint32_t(MP_MAP_PAGES * MP_MAP_PAGES);
      }
    } else {
      d.kind = MP_SHADOW_CUBE;
      d.levels = MP_CUBE_MIPS;
      if (l.type == Light::Type::Area) {
        d.shape = l.shape == Light::Shape::Ellipse ? MP_SHADOW_SHAPE_ELLIPSE : MP_SHADOW_SHAPE_RECTANGLE;
        d.size[0] = 0.5f * l.size_u, d.size[1] = 0.5f * l.size_v;
        if (!(std::max(d.size[0], d.size[1]) > 0.0f)) d.shape = MP_SHADOW_SHAPE_POINT;
      } else {
        d.shape = l.radius > 0.0f ? MP_SHADOW_SHAPE_DISK : MP_SHADOW_SHAPE_POINT;
        d.size[0] = d.size[1] = l.radius;
      }
      const float near = float(std::max(1e-5 * diagonal, 1e-7));
      for (int face = 0; face < 6; ++face) {
        const glm::dmat3 fr = face_rotation(face);
        for (int mip = 0; mip < MP_CUBE_MIPS; ++mip) {
          ShadowMapInfo m;
          m.light = int(i);
          m.map_id = face * MP_CUBE_MIPS + mip;
          m.table = out.table_entries + uint32_t(face) * MP_CUBE_FACE_ENTRIES + mp_cube_mip_entries(mip);
          m.side = MP_MAP_PAGES >> mip;
          m.coarseness = mip;
          FrameParams& v = m.view = base;
          put_rows(v.view, fr * r, fr * t);
          v.ortho = 0;
          v.ax = v.ay = v.bx = v.by = 0.5f * float(mp_cube_mip_texels(mip));
          v.width = v.height = mp_cube_mip_texels(mip);
          v.clip_near = near;
          v.clip_far = 3.0e38f;
          v.eye_epsilon = 0.5f * near;
          v.page_table = m.table;
          v.page_side = m.side;
          v.page_origin_x = v.page_origin_y = 0;
          out.maps.push_back(m);
        }
      }
      out.table_entries += 6u * MP_CUBE_FACE_ENTRIES;
    }
    out.light_keys[i] = shadow_light_key(l, geometry_key, s, d.z_top);
    ++out.shadowed_lights;
  }
  return out;
}

void set_shadow_level_bias(ShadowLayout& layout, int bias) {
  for (size_t i = 0; i < layout.shadows.size(); ++i) layout.shadows[i].level_bias = layout.own_bias[i] + bias;
}

}  // namespace mp
