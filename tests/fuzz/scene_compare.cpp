#include "scene_compare.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <glm/glm.hpp>

namespace mp::fuzz {
namespace {

// Collects the first difference; later checks are skipped once one is found.
class Diff {
 public:
  bool found() const { return !text_.empty(); }
  const std::string& text() const { return text_; }

  template <typename T>
  void eq(const std::string& path, const T& a, const T& b) {
    if (found() || same(a, b)) return;
    std::ostringstream s;
    s.precision(9);
    s << path << ": ";
    print(s, a);
    s << " vs ";
    print(s, b);
    text_ = s.str();
  }
  void fail(const std::string& what) {
    if (!found()) text_ = what;
  }

 private:
  // Exact float equality; NaN equals NaN (the reader should reject NaN, but
  // a NaN that survives both readings is not a round-trip difference).
  static bool same(float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }
  static bool same(int a, int b) { return a == b; }
  static bool same(bool a, bool b) { return a == b; }
  static bool same(const std::string& a, const std::string& b) { return a == b; }
  template <int N>
  static bool same(const glm::vec<N, float>& a, const glm::vec<N, float>& b) {
    for (int i = 0; i < N; ++i)
      if (!same(a[i], b[i])) return false;
    return true;
  }
  static bool same(const glm::mat4& a, const glm::mat4& b) {
    for (int c = 0; c < 4; ++c)
      if (!same(a[c], b[c])) return false;
    return true;
  }
  template <typename T>
  static bool same(const std::vector<T>& a, const std::vector<T>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
      if (!same(a[i], b[i])) return false;
    return true;
  }
  template <typename E, typename = std::enable_if_t<std::is_enum_v<E>>>
  static bool same(E a, E b) { return a == b; }

  template <typename T>
  static void print(std::ostream& s, const T& v) {
    if constexpr (std::is_enum_v<T>) {
      s << static_cast<int>(v);
    } else if constexpr (std::is_same_v<T, glm::mat4>) {
      for (int c = 0; c < 4; ++c) print(s, glm::vec4(v[c]));
    } else if constexpr (std::is_same_v<T, glm::vec2> || std::is_same_v<T, glm::vec3> ||
                         std::is_same_v<T, glm::vec4>) {
      s << '(';
      for (int i = 0; i < T::length(); ++i) s << (i ? " " : "") << v[i];
      s << ')';
    } else if constexpr (std::is_same_v<T, std::string>) {
      s << '"' << v << '"';
    } else if constexpr (std::is_arithmetic_v<T>) {
      s << v;
    } else {  // vectors: their size and first differing element is enough to debug
      s << "[" << v.size() << " items";
      if (!v.empty()) {
        s << ", first ";
        print(s, v.front());
      }
      s << "]";
    }
  }

  std::string text_;
};

void compare_settings(Diff& d, const RenderSettings& a, const RenderSettings& b) {
  d.eq("settings.width", a.width, b.width);
  d.eq("settings.height", a.height, b.height);
  d.eq("settings.pixel_aspect", a.pixel_aspect, b.pixel_aspect);
  d.eq("settings.crop_x0", a.crop_x0, b.crop_x0);
  d.eq("settings.crop_x1", a.crop_x1, b.crop_x1);
  d.eq("settings.crop_y0", a.crop_y0, b.crop_y0);
  d.eq("settings.crop_y1", a.crop_y1, b.crop_y1);
  d.eq("settings.samples_x", a.samples_x, b.samples_x);
  d.eq("settings.samples_y", a.samples_y, b.samples_y);
  d.eq("settings.shading_rate", a.shading_rate, b.shading_rate);
  d.eq("settings.filter", a.filter, b.filter);
  d.eq("settings.filter_width", a.filter_width, b.filter_width);
  d.eq("settings.bound_split", a.bound_split, b.bound_split);
  d.eq("settings.bound_split_memory_mib", a.bound_split_memory_mib, b.bound_split_memory_mib);
  d.eq("settings.max_grid_size", a.max_grid_size, b.max_grid_size);
  d.eq("settings.max_split_depth", a.max_split_depth, b.max_split_depth);
  d.eq("settings.backface_culling", a.backface_culling, b.backface_culling);
  d.eq("settings.depth_and_normal_passes", a.depth_and_normal_passes, b.depth_and_normal_passes);
  d.eq("settings.shadows", a.shadows, b.shadows);
  d.eq("settings.shadow_memory_mib", a.shadow_memory_mib, b.shadow_memory_mib);
  d.eq("settings.shadow_shading_rate", a.shadow_shading_rate, b.shadow_shading_rate);
  d.eq("settings.occlusion_culling", a.occlusion_culling, b.occlusion_culling);
  d.eq("settings.holdout_covers", a.holdout_covers, b.holdout_covers);
  d.eq("settings.resolver", a.resolver, b.resolver);
  d.eq("settings.occlusion_waves", a.occlusion_waves, b.occlusion_waves);
  d.eq("settings.bound_split_chain", a.bound_split_chain, b.bound_split_chain);
  d.eq("settings.bound_split_steps", a.bound_split_steps, b.bound_split_steps);
}

void compare_camera(Diff& d, const Camera& a, const Camera& b) {
  d.eq("camera.projection", a.projection, b.projection);
  d.eq("camera.world_to_camera", a.world_to_camera, b.world_to_camera);
  d.eq("camera.motion_world_to_camera", a.motion_world_to_camera, b.motion_world_to_camera);
  if (a.projection == Camera::Projection::Perspective) d.eq("camera.fov_degrees", a.fov_degrees, b.fov_degrees);
  if (a.screen_left != a.screen_right || a.screen_bottom != a.screen_top) {
    d.eq("camera.screen_left", a.screen_left, b.screen_left);
    d.eq("camera.screen_right", a.screen_right, b.screen_right);
    d.eq("camera.screen_bottom", a.screen_bottom, b.screen_bottom);
    d.eq("camera.screen_top", a.screen_top, b.screen_top);
  } else if (b.screen_left != b.screen_right) {
    d.fail("camera.screen window: derived from the aspect ratio, read back as explicit");
  }
  // RenderMan's Clipping needs near > 0: the writer turns 0 into the
  // smallest positive float.
  const float near = a.clip_near > 0 ? a.clip_near : std::numeric_limits<float>::denorm_min();
  d.eq("camera.clip_near", near, b.clip_near);
  d.eq("camera.clip_far", a.clip_far, b.clip_far);
  d.eq("camera.lens_radius", a.lens_radius, b.lens_radius);
  if (a.lens_radius > 0.0f) {
    d.eq("camera.focus_distance", a.focus_distance, b.focus_distance);
    d.eq("camera.aperture_blades", a.aperture_blades, b.aperture_blades);
    d.eq("camera.aperture_rotation", a.aperture_rotation, b.aperture_rotation);
    d.eq("camera.aperture_ratio", a.aperture_ratio, b.aperture_ratio);
  }
}

// Only the fields the material's model shades with (scene.h): the others
// have no effect, and the writer need not carry them.
void compare_material(Diff& d, const std::string& p, const Material& a, const Material& b) {
  d.eq(p + ".name", a.name, b.name);
  d.eq(p + ".model", a.model, b.model);
  d.eq(p + ".color", a.color, b.color);
  d.eq(p + ".opacity", a.opacity, b.opacity);
  d.eq(p + ".emission", a.emission, b.emission);
  switch (a.model) {
    case Material::Model::Constant: break;
    case Material::Model::Plastic:
      d.eq(p + ".ks", a.ks, b.ks);
      d.eq(p + ".roughness", a.roughness, b.roughness);
      d.eq(p + ".specular_color", a.specular_color, b.specular_color);
      [[fallthrough]];
    case Material::Model::Matte:
      d.eq(p + ".ka", a.ka, b.ka);
      d.eq(p + ".kd", a.kd, b.kd);
      break;
    case Material::Model::Principled:
      d.eq(p + ".metallic", a.metallic, b.metallic);
      d.eq(p + ".roughness", a.roughness, b.roughness);
      d.eq(p + ".specular", a.specular, b.specular);
      d.eq(p + ".layered", a.layered, b.layered);
      d.eq(p + ".retro_diffuse", a.retro_diffuse, b.retro_diffuse);
      d.eq(p + ".multiscatter", a.multiscatter, b.multiscatter);
      break;
  }
  d.eq(p + ".program", a.program, b.program);
  if (a.program >= 0) {
    d.eq(p + ".program_displaces", a.program_displaces, b.program_displaces);
    d.eq(p + ".program_shades", a.program_shades, b.program_shades);
    d.eq(p + ".program_alpha", a.program_alpha, b.program_alpha);
    d.eq(p + ".program_alpha_cut", a.program_alpha_cut, b.program_alpha_cut);
    d.eq(p + ".displacement_bound", a.displacement_bound, b.displacement_bound);
    d.eq(p + ".displacement_bound_world", a.displacement_bound_world, b.displacement_bound_world);
  }
}

// As the types use them (scene.h, Light). Directions that are not unit
// length come back normalised (RenderMan lights give a from/to pair), so
// those are compared to a few ulps of the normalised direction.
void compare_light(Diff& d, const std::string& p, const Light& a, const Light& b) {
  d.eq(p + ".type", a.type, b.type);
  d.eq(p + ".color", a.color, b.color);
  d.eq(p + ".intensity", a.intensity, b.intensity);
  if (a.type == Light::Type::Ambient) {
    d.eq(p + ".cast_shadows (ambient lights cast none)", false, b.cast_shadows);
    return;
  }
  d.eq(p + ".position", a.position, b.position);
  d.eq(p + ".cast_shadows", a.cast_shadows, b.cast_shadows);
  if (a.type == Light::Type::Point || a.type == Light::Type::Spot) {
    d.eq(p + ".radius", a.radius, b.radius);
    d.eq(p + ".soft_falloff", a.soft_falloff, b.soft_falloff);
  }
  if (a.type == Light::Type::Distant) d.eq(p + ".angle", a.angle, b.angle);
  if (a.type == Light::Type::Point) return;
  const float len = glm::length(a.direction);
  if (std::fabs(len - 1.0f) < 1e-6f) {
    d.eq(p + ".direction", a.direction, b.direction);
  } else if (len > 0.0f && std::isfinite(len)) {
    const glm::vec3 n = a.direction / len;
    const glm::vec3 e = glm::abs(b.direction - n);
    if (e.x > 1e-6f || e.y > 1e-6f || e.z > 1e-6f) d.eq(p + ".direction (normalised)", n, b.direction);
  }
  if (a.type == Light::Type::Spot) {
    d.eq(p + ".cone_angle", a.cone_angle, b.cone_angle);
    d.eq(p + ".cone_delta_angle", a.cone_delta_angle, b.cone_delta_angle);
    d.eq(p + ".beam_distribution", a.beam_distribution, b.beam_distribution);
  }
  if (a.type == Light::Type::Area) {
    d.eq(p + ".shape", a.shape, b.shape);
    d.eq(p + ".axis_u", a.axis_u, b.axis_u);
    d.eq(p + ".size_u", a.size_u, b.size_u);
    d.eq(p + ".size_v", a.size_v, b.size_v);
  }
}

void compare_info(Diff& d, const std::string& p, const ObjectInfo& a, const ObjectInfo& b) {
  d.eq(p + ".info.color", a.color, b.color);
  d.eq(p + ".info.pass_index", a.pass_index, b.pass_index);
  d.eq(p + ".info.random", a.random, b.random);
}

void compare_mesh(Diff& d, const std::string& p, const Mesh& a, const Mesh& b) {
  d.eq(p + ".name", a.name, b.name);
  d.eq(p + ".scheme", a.scheme, b.scheme);
  d.eq(p + ".points", a.points, b.points);
  d.eq(p + ".motion_points", a.motion_points, b.motion_points);
  d.eq(p + ".motion_object_to_world", a.motion_object_to_world, b.motion_object_to_world);
  d.eq(p + ".face_vertex_counts", a.face_vertex_counts, b.face_vertex_counts);
  d.eq(p + ".face_vertex_indices", a.face_vertex_indices, b.face_vertex_indices);
  if (a.scheme == SubdivScheme::CatmullClark) {  // tags only Catmull-Clark meshes use
    d.eq(p + ".crease_vertices", a.crease_vertices, b.crease_vertices);
    d.eq(p + ".crease_sharpness", a.crease_sharpness, b.crease_sharpness);
    d.eq(p + ".corner_vertices", a.corner_vertices, b.corner_vertices);
    d.eq(p + ".corner_sharpness", a.corner_sharpness, b.corner_sharpness);
    d.eq(p + ".hole_faces", a.hole_faces, b.hole_faces);
    d.eq(p + ".boundary", a.boundary, b.boundary);
  }
  d.eq(p + ".material", a.material, b.material);
  d.eq(p + ".face_materials", a.face_materials, b.face_materials);
  d.eq(p + ".object_to_world", a.object_to_world, b.object_to_world);
  d.eq(p + ".double_sided", a.double_sided, b.double_sided);
  d.eq(p + ".visible_camera", a.visible_camera, b.visible_camera);
  d.eq(p + ".cast_shadows", a.cast_shadows, b.cast_shadows);
  compare_info(d, p, a.info, b.info);
  d.eq(p + ".uv_layers", a.uv_layers, b.uv_layers);
  d.eq(p + ".corner_normals", a.corner_normals, b.corner_normals);
  d.eq(p + ".texspace_location", a.texspace_location, b.texspace_location);
  d.eq(p + ".texspace_size", a.texspace_size, b.texspace_size);
}

void compare_patches(Diff& d, const std::string& p, const BezierPatches& a, const BezierPatches& b) {
  d.eq(p + ".name", a.name, b.name);
  d.eq(p + ".control_points", a.control_points, b.control_points);
  d.eq(p + ".material", a.material, b.material);
  d.eq(p + ".object_to_world", a.object_to_world, b.object_to_world);
  d.eq(p + ".double_sided", a.double_sided, b.double_sided);
  d.eq(p + ".visible_camera", a.visible_camera, b.visible_camera);
  d.eq(p + ".cast_shadows", a.cast_shadows, b.cast_shadows);
  compare_info(d, p, a.info, b.info);
}

void compare_world(Diff& d, const World& a, const World& b) {
  d.eq("world.program", a.program, b.program);
  if (a.program >= 0) d.eq("world.bake_width", a.bake_width, b.bake_width);
  d.eq("world.width", a.width, b.width);
  d.eq("world.height", a.height, b.height);
  d.eq("world.radiance", a.radiance, b.radiance);
  if (a.present()) {
    d.eq("world.camera", a.camera, b.camera);
    d.eq("world.diffuse", a.diffuse, b.diffuse);
    d.eq("world.glossy", a.glossy, b.glossy);
    d.eq("world.cast_shadows", a.cast_shadows, b.cast_shadows);
  }
}

std::string item(const char* what, size_t i) { return std::string(what) + "[" + std::to_string(i) + "]"; }

}  // namespace

std::string first_difference(const Scene& a, const Scene& b) {
  Diff d;
  compare_settings(d, a.settings, b.settings);
  d.eq("motion_steps", a.motion_steps, b.motion_steps);
  d.eq("shutter_curve", a.shutter_curve, b.shutter_curve);
  compare_camera(d, a.camera, b.camera);
  if (a.materials.empty()) {  // rendered with Material{}, written as material 0
    d.eq("materials.size (default material)", 1, int(b.materials.size()));
    if (!d.found()) compare_material(d, "materials[0]", Material{}, b.materials[0]);
  } else {
    d.eq("materials.size", int(a.materials.size()), int(b.materials.size()));
    for (size_t i = 0; i < a.materials.size() && !d.found(); ++i)
      compare_material(d, item("materials", i), a.materials[i], b.materials[i]);
  }
  d.eq("material_programs.size", int(a.material_programs.size()), int(b.material_programs.size()));
  for (size_t i = 0; i < a.material_programs.size() && !d.found(); ++i)
    d.eq(item("material_programs", i) + ".source", a.material_programs[i].source, b.material_programs[i].source);
  d.eq("images.size", int(a.images.size()), int(b.images.size()));
  for (size_t i = 0; i < a.images.size() && !d.found(); ++i) {
    const Image &x = a.images[i], &y = b.images[i];
    const std::string p = item("images", i);
    d.eq(p + ".name", x.name, y.name);
    d.eq(p + ".width", x.width, y.width);
    d.eq(p + ".height", x.height, y.height);
    d.eq(p + ".pixels", x.pixels, y.pixels);
    d.eq(p + ".srgb", x.srgb, y.srgb);
  }
  d.eq("lights.size", int(a.lights.size()), int(b.lights.size()));
  for (size_t i = 0; i < a.lights.size() && !d.found(); ++i) compare_light(d, item("lights", i), a.lights[i], b.lights[i]);
  compare_world(d, a.world, b.world);
  d.eq("meshes.size", int(a.meshes.size()), int(b.meshes.size()));
  for (size_t i = 0; i < a.meshes.size() && !d.found(); ++i) compare_mesh(d, item("meshes", i), a.meshes[i], b.meshes[i]);
  d.eq("bezier_patches.size", int(a.bezier_patches.size()), int(b.bezier_patches.size()));
  for (size_t i = 0; i < a.bezier_patches.size() && !d.found(); ++i)
    compare_patches(d, item("bezier_patches", i), a.bezier_patches[i], b.bezier_patches[i]);
  return d.text();
}

}  // namespace mp::fuzz
