// Scene validation: the one place bad input is caught, with a message that
// names the object, so the pipeline never sees NaNs or out-of-range indices.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "micropoly/error.h"
#include "micropoly/scene.h"
#include "geometry/mp_patch.h"

namespace mp {
namespace {

// The decimal number at source[i], after any blanks, and the blanks after
// it; i moves past them. False where there is none. A number too long to
// be an index reads as the largest, so the program is refused.
void skip_blanks(const std::string& source, size_t& i) {
  while (i < source.size() && std::isspace(static_cast<unsigned char>(source[i]))) ++i;
}

bool read_count(const std::string& source, size_t& i, size_t& value) {
  size_t digits = 0;
  value = 0;
  skip_blanks(source, i);
  for (; i < source.size() && std::isdigit(static_cast<unsigned char>(source[i])); ++i, ++digits)
    value = digits < 12 ? 10 * value + size_t(source[i] - '0') : size_t(1) << 40;
  skip_blanks(source, i);
  return digits > 0;
}

// How many node values a program reads: past the last value of every
// MP_PARAM(k), MP_PARAM3(k), MP_PARAM4(k) and MP_PARAM_TABLE(k, n)
// (kernels/materials/mp_node_lib.h).
size_t program_param_count(const std::string& source) {
  static const std::string table = "_TABLE(";
  size_t need = 0;
  for (size_t at = source.find("MP_PARAM"); at != std::string::npos; at = source.find("MP_PARAM", at + 1)) {
    size_t i = at + 8, k = 0, width = 1;
    const bool is_table = source.compare(i, table.size(), table) == 0;
    if (is_table) i += table.size() - 1;
    else if (i < source.size() && (source[i] == '3' || source[i] == '4')) width = size_t(source[i++] - '0');
    skip_blanks(source, i);
    if (i >= source.size() || source[i] != '(' || !read_count(source, ++i, k)) continue;
    if (is_table && (i >= source.size() || source[i] != ',' || !read_count(source, ++i, width))) continue;
    if (i < source.size() && source[i] == ')') need = std::max(need, k + width);
  }
  return need;
}

// A material's or the world's node values: as many as its program reads
// (`need`, program_param_count), all finite.
void check_program_params(const std::vector<float>& params, size_t need, const std::string& owner) {
  if (params.size() < need)
    throw Error(owner + ": its program reads " + std::to_string(need) + " node values, but it has " +
                std::to_string(params.size()));
  for (float v : params)
    if (!std::isfinite(v)) throw Error(owner + ": a node value is NaN or infinite");
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool finite(const glm::vec4& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w); }

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& why) {
  throw Error(what + " '" + name + "': " + why);
}

void check_material_index(int index, size_t count, const std::string& what, const std::string& name) {
  size_t available = count == 0 ? 1 : count;
  if (index < 0 || static_cast<size_t>(index) >= available)
    fail(what, name, "material index " + std::to_string(index) + " out of range (" + std::to_string(available) + " materials)");
}

// World-space coordinates beyond this are refused. The pipeline works in
// single precision, where squared distances overflow past ~1.8e19 and a
// triangle spanning ~1e25 keeps bound-and-split busy for minutes on NaN
// bounds; 1e15 scene units (0.1 light-year in metres) leaves a wide margin
// and no real scene near it.
constexpr float kMaxWorldCoordinate = 1e15f;

// Every point of `points` through `to_world` lies within kMaxWorldCoordinate.
void check_extent(const std::vector<glm::vec3>& points, const glm::mat4& to_world, const char* what,
                  const std::string& name) {
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::vec4 w = to_world * glm::vec4(points[i], 1.0f);
    const float reach = std::max({std::abs(w.x), std::abs(w.y), std::abs(w.z)});
    if (!(reach <= kMaxWorldCoordinate)) {
      char far[32];
      std::snprintf(far, sizeof far, "%.3g", double(reach));
      fail(what, name, "point " + std::to_string(i) + " lies " + far +
                           " units from the origin; coordinates beyond 1e15 are refused (single-precision rendering)");
    }
  }
}

// Motion steps of a mesh: one per Scene step, the topology's point count
// each (the same patches move), finite.
void validate_mesh_motion(const Mesh& m, size_t steps) {
  const char* what = "mesh";
  if (!m.motion_object_to_world.empty()) {
    if (m.motion_object_to_world.size() != steps)
      fail(what, m.name, "has " + std::to_string(m.motion_object_to_world.size()) + " motion transforms for " +
                             std::to_string(steps) + " motion steps");
    for (const glm::mat4& t : m.motion_object_to_world)
      if (!finite(t)) fail(what, m.name, "has a motion transform with NaN or infinite values");
    if (m.motion_points.empty())
      for (const glm::mat4& t : m.motion_object_to_world) check_extent(m.points, t, what, m.name);
  }
  if (m.motion_points.empty()) return;
  if (m.motion_points.size() != steps)
    fail(what, m.name, "has " + std::to_string(m.motion_points.size()) + " sets of motion points for " +
                           std::to_string(steps) + " motion steps");
  for (size_t k = 0; k < steps; ++k) {
    if (m.motion_points[k].size() != m.points.size())
      fail(what, m.name, "changes its topology during the shutter: motion step " + std::to_string(k) + " has " +
                             std::to_string(m.motion_points[k].size()) + " points, not " +
                             std::to_string(m.points.size()));
    for (const glm::vec3& p : m.motion_points[k])
      if (!finite(p)) fail(what, m.name, "has a NaN or infinite motion point at step " + std::to_string(k));
  }
  for (size_t k = 0; k < steps; ++k)
    check_extent(m.motion_points[k], m.motion_object_to_world.empty() ? m.object_to_world : m.motion_object_to_world[k],
                 what, m.name);
}

// Motion steps of a patch set, as of a mesh: one per Scene step, the same
// number of control points each, finite.
void validate_patches_motion(const BezierPatches& b, size_t steps) {
  const char* what = "patch set";
  if (!b.motion_object_to_world.empty()) {
    if (b.motion_object_to_world.size() != steps)
      fail(what, b.name, "has " + std::to_string(b.motion_object_to_world.size()) + " motion transforms for " +
                             std::to_string(steps) + " motion steps");
    for (const glm::mat4& t : b.motion_object_to_world)
      if (!finite(t)) fail(what, b.name, "has a motion transform with NaN or infinite values");
  }
  if (b.motion_control_points.empty()) return;
  if (b.motion_control_points.size() != steps)
    fail(what, b.name, "has " + std::to_string(b.motion_control_points.size()) + " sets of motion points for " +
                           std::to_string(steps) + " motion steps");
  for (size_t k = 0; k < steps; ++k) {
    if (b.motion_control_points[k].size() != b.control_points.size())
      fail(what, b.name, "changes its patches during the shutter: motion step " + std::to_string(k) + " has " +
                             std::to_string(b.motion_control_points[k].size()) + " control points, not " +
                             std::to_string(b.control_points.size()));
    for (const glm::vec3& p : b.motion_control_points[k])
      if (!finite(p)) fail(what, b.name, "has a NaN or infinite motion point at step " + std::to_string(k));
    check_extent(b.motion_control_points[k],
                 b.motion_object_to_world.empty() ? b.object_to_world : b.motion_object_to_world[k], what, b.name);
  }
}

void validate_mesh(const Mesh& m, size_t materials) {
  const char* what = "mesh";
  if (!finite(m.object_to_world)) fail(what, m.name, "transform contains NaN or infinite values");
  for (size_t i = 0; i < m.points.size(); ++i)
    if (!finite(m.points[i]))
      fail(what, m.name, "vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
  check_extent(m.points, m.object_to_world, what, m.name);
  size_t total = 0;
  for (size_t f = 0; f < m.face_vertex_counts.size(); ++f) {
    int n = m.face_vertex_counts[f];
    if (n < 3) fail(what, m.name, "face " + std::to_string(f) + " has " + std::to_string(n) + " vertices (at least 3 needed)");
    total += static_cast<size_t>(n);
  }
  if (total != m.face_vertex_indices.size())
    fail(what, m.name, "face vertex counts add up to " + std::to_string(total) + " but there are " +
                           std::to_string(m.face_vertex_indices.size()) + " face vertex indices");
  for (size_t i = 0; i < m.face_vertex_indices.size(); ++i) {
    int v = m.face_vertex_indices[i];
    if (v < 0 || static_cast<size_t>(v) >= m.points.size())
      fail(what, m.name, "face vertex index " + std::to_string(v) + " out of range (" + std::to_string(m.points.size()) + " vertices)");
  }
  if (m.crease_vertices.size() != 2 * m.crease_sharpness.size())
    fail(what, m.name, "crease data needs two vertex indices per sharpness value");
  for (int v : m.crease_vertices)
    if (v < 0 || static_cast<size_t>(v) >= m.points.size()) fail(what, m.name, "crease vertex index out of range");
  if (m.corner_vertices.size() != m.corner_sharpness.size())
    fail(what, m.name, "corner data needs one sharpness value per corner vertex");
  for (int v : m.corner_vertices)
    if (v < 0 || static_cast<size_t>(v) >= m.points.size()) fail(what, m.name, "corner vertex index out of range");
  for (float s : m.crease_sharpness)
    if (!std::isfinite(s) || s < 0) fail(what, m.name, "crease sharpness must be finite and >= 0");
  for (float s : m.corner_sharpness)
    if (!std::isfinite(s) || s < 0) fail(what, m.name, "corner sharpness must be finite and >= 0");
  for (int h : m.hole_faces)
    if (h < 0 || static_cast<size_t>(h) >= m.face_vertex_counts.size()) fail(what, m.name, "hole face index out of range");
  if (m.uv_layers.size() > MP_MAX_UV_LAYERS)
    fail(what, m.name, "has " + std::to_string(m.uv_layers.size()) + " UV maps; at most " +
                           std::to_string(MP_MAX_UV_LAYERS) + " are supported");
  for (size_t k = 0; k < m.uv_layers.size(); ++k) {
    if (m.uv_layers[k].size() != m.face_vertex_indices.size())
      fail(what, m.name, "UV map " + std::to_string(k) + " has " + std::to_string(m.uv_layers[k].size()) +
                             " values; it needs one per face corner (" + std::to_string(m.face_vertex_indices.size()) + ")");
    for (const glm::vec2& uv : m.uv_layers[k])
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) fail(what, m.name, "UV map " + std::to_string(k) + " has a NaN or infinite value");
  }
  if (!m.corner_normals.empty()) {
    if (m.corner_normals.size() != m.face_vertex_indices.size())
      fail(what, m.name, "has " + std::to_string(m.corner_normals.size()) + " corner normals; it needs one per face corner (" +
                             std::to_string(m.face_vertex_indices.size()) + ") or none");
    for (const glm::vec3& n : m.corner_normals)
      if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
        fail(what, m.name, "has a NaN or infinite corner normal");
  }
  check_material_index(m.material, materials, what, m.name);
  if (!m.face_materials.empty()) {
    if (m.face_materials.size() != m.face_vertex_counts.size())
      fail(what, m.name, "needs one material index per face (" + std::to_string(m.face_vertex_counts.size()) + "), got " +
                             std::to_string(m.face_materials.size()));
    for (int idx : m.face_materials) check_material_index(idx, materials, what, m.name);
  }
}

}  // namespace

void validate_patches(const BezierPatches& b, size_t materials) {
  if (b.control_points.size() % 16 != 0) fail("patch set", b.name, "needs 16 control points per bicubic patch");
  for (const glm::vec3& p : b.control_points)
    if (!finite(p)) fail("patch set", b.name, "has a NaN or infinite control point");
  if (!finite(b.object_to_world)) fail("patch set", b.name, "transform contains NaN or infinite values");
  check_extent(b.control_points, b.object_to_world, "patch set", b.name);
  check_material_index(b.material, materials, "patch set", b.name);
  if (b.uv_layers.size() > MP_MAX_UV_LAYERS)
    fail("patch set", b.name, "has " + std::to_string(b.uv_layers.size()) + " UV layers; at most " +
                                  std::to_string(MP_MAX_UV_LAYERS) + " are supported");
  for (const auto& layer : b.uv_layers) {
    if (layer.size() != b.control_points.size() / 4)
      fail("patch set", b.name, "has a UV layer of " + std::to_string(layer.size()) + " values; it needs 4 per patch (" +
                                    std::to_string(b.control_points.size() / 4) + ")");
    for (const glm::vec2& uv : layer)
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) fail("patch set", b.name, "has a NaN or infinite UV value");
  }
}

// Prototypes are checked once, in their own space; each instance by its
// transforms and the prototype's box carried through them, so a million
// instances cost a million boxes, not a million meshes.
void validate_instances(const Scene& scene) {
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  for (const Prototype& proto : scene.prototypes) {
    glm::vec3 lo(0.0f), hi(0.0f);
    bool any = false;
    auto grow = [&](const std::vector<glm::vec3>& points, const glm::mat4& m) {
      for (const glm::vec3& p : points) {
        const glm::vec3 q(m * glm::vec4(p, 1.0f));
        lo = any ? glm::min(lo, q) : q, hi = any ? glm::max(hi, q) : q, any = true;
      }
    };
    for (const Mesh& m : proto.meshes) {
      validate_mesh(m, scene.materials.size());
      if (!m.motion_points.empty() || !m.motion_object_to_world.empty())
        fail("prototype", proto.name, "mesh '" + m.name + "' moves on its own; instances move, their prototypes do not");
      grow(m.points, m.object_to_world);
    }
    for (const BezierPatches& b : proto.bezier_patches) {
      validate_patches(b, scene.materials.size());
      grow(b.control_points, b.object_to_world);
    }
    boxes.emplace_back(lo, hi);
  }
  const size_t steps = size_t(scene.motion_steps);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const std::string name = std::to_string(i);
    if (inst.prototype < 0 || size_t(inst.prototype) >= scene.prototypes.size())
      fail("instance", name, "places prototype " + std::to_string(inst.prototype) + " of " +
                                 std::to_string(scene.prototypes.size()));
    if (inst.material != -1) check_material_index(inst.material, scene.materials.size(), "instance", name);
    if (inst.double_sided < -1 || inst.double_sided > 1)
      fail("instance", name, "double_sided must be -1 (the surfaces' own), 0 or 1");
    if (!finite(inst.info.color) || !std::isfinite(inst.info.pass_index) || !std::isfinite(inst.info.random) ||
        !std::all_of(inst.info.attributes.begin(), inst.info.attributes.end(),
                     [&](const glm::vec4& a) { return finite(a); }))
      fail("instance", name, "has NaN or infinite Object Info values");
    if (!inst.motion_object_to_world.empty() && inst.motion_object_to_world.size() != steps)
      fail("instance", name, "has " + std::to_string(inst.motion_object_to_world.size()) +
                                 " motion transforms for " + std::to_string(steps) + " motion steps");
    const auto& box = boxes[size_t(inst.prototype)];
    std::vector<glm::vec3> corners;
    for (int c = 0; c < 8; ++c)
      corners.emplace_back(c & 1 ? box.second.x : box.first.x, c & 2 ? box.second.y : box.first.y,
                           c & 4 ? box.second.z : box.first.z);
    if (!finite(inst.object_to_world)) fail("instance", name, "transform contains NaN or infinite values");
    check_extent(corners, inst.object_to_world, "instance", name);
    for (const glm::mat4& t : inst.motion_object_to_world) {
      if (!finite(t)) fail("instance", name, "has a motion transform with NaN or infinite values");
      check_extent(corners, t, "instance", name);
    }
  }
}

void validate_scene(const Scene& scene) {
  const RenderSettings& s = scene.settings;
  if (s.width < 1 || s.height < 1 || s.width > 65536 || s.height > 65536)
    throw Error("image size " + std::to_string(s.width) + "x" + std::to_string(s.height) + " is out of range (1..65536)");
  if (!(s.pixel_aspect > 0) || !std::isfinite(s.pixel_aspect)) throw Error("pixel aspect must be a positive number");
  // The product in 64 bits: two large counts would overflow an int (and
  // could wrap to a small one that passes).
  if (s.samples_x < 1 || s.samples_y < 1 || int64_t(s.samples_x) * int64_t(s.samples_y) > 1024)
    throw Error("samples per pixel must be between 1 and 1024");
  if (!(s.shading_rate > 0) || !std::isfinite(s.shading_rate)) throw Error("shading rate must be a positive number");
  if (!(s.filter_width > 0) || s.filter_width > 16) throw Error("pixel filter width must be in (0, 16]");
  if (!(s.crop_x0 < s.crop_x1) || !(s.crop_y0 < s.crop_y1) || s.crop_x0 < 0 || s.crop_y0 < 0 || s.crop_x1 > 1 || s.crop_y1 > 1)
    throw Error("crop window must satisfy 0 <= min < max <= 1");
  if (!(s.bound_split_memory_mib > 0) || !std::isfinite(s.bound_split_memory_mib))
    throw Error("bound & split memory budget must be a positive number of MiB");
  if (s.bound_split_chain < 1 || s.bound_split_chain > 1024)
    throw Error("bound & split chain must be 1 to 1024 launches");
  if (s.bound_split_steps < 0 || s.bound_split_steps > 1024)
    throw Error("bound & split steps per launch must be 0 (auto) to 1024");
  if (!(s.shadow_memory_mib > 0) || !std::isfinite(s.shadow_memory_mib))
    throw Error("shadow map memory budget must be a positive number of MiB");
  if (!(s.shadow_shading_rate > 0) || !std::isfinite(s.shadow_shading_rate))
    throw Error("shadow shading rate must be a positive number");
  if (!(s.texture_filter_width >= 0.0f && s.texture_filter_width <= 16.0f))
    throw Error("texture filter width must be 0 to 16");

  const Camera& c = scene.camera;
  if (!finite(c.world_to_camera)) throw Error("camera transform contains NaN or infinite values");
  if (std::abs(glm::determinant(glm::mat3(c.world_to_camera))) < 1e-12f) throw Error("camera transform is degenerate");
  // The whole 4x4 transform must be invertible too (a projective bottom row
  // can make it singular where its 3x3 part is not), by the RIB reader's
  // own test at WorldBegin, so that every valid camera writes to RIB and
  // reads back.
  const float camera_det = glm::determinant(c.world_to_camera);
  if (!std::isfinite(camera_det) || std::abs(camera_det) < 1e-30f) throw Error("camera transform is singular");
  if (c.projection == Camera::Projection::Perspective && !(c.fov_degrees > 0 && c.fov_degrees < 180))
    throw Error("camera field of view must be between 0 and 180 degrees");
  if (!(c.clip_near >= 0) || !(c.clip_far > c.clip_near) || !std::isfinite(c.clip_far))
    throw Error("camera clipping range must satisfy 0 <= near < far < infinity");
  bool window_set = c.screen_right != c.screen_left || c.screen_top != c.screen_bottom;
  if (window_set && !(c.screen_right > c.screen_left && c.screen_top > c.screen_bottom))
    throw Error("camera screen window must have left < right and bottom < top");
  if (!(c.lens_radius >= 0) || !std::isfinite(c.lens_radius))
    throw Error("camera aperture radius must be a finite number >= 0");
  if (c.lens_radius > 0) {
    if (!(c.focus_distance > 0) || !std::isfinite(c.focus_distance))
      throw Error("camera focus distance must be a positive number when depth of field is on");
    if (!(c.aperture_ratio > 0) || !std::isfinite(c.aperture_ratio))
      throw Error("camera aperture ratio must be a positive number");
    if (!std::isfinite(c.aperture_rotation) || c.aperture_blades < 0 || c.aperture_blades > Camera::kMaxApertureBlades)
      throw Error("camera aperture blades must be in [0, " + std::to_string(Camera::kMaxApertureBlades) +
                  "] and its rotation finite");
  }
  if (scene.motion_steps != 0 && (scene.motion_steps < 2 || scene.motion_steps > kMaxMotionSteps))
    throw Error("motion blur needs 2 to " + std::to_string(kMaxMotionSteps) + " motion steps, not " +
                std::to_string(scene.motion_steps));
  const size_t steps = size_t(scene.motion_steps);
  if (!c.motion_world_to_camera.empty()) {
    if (c.motion_world_to_camera.size() != steps)
      throw Error("the camera has " + std::to_string(c.motion_world_to_camera.size()) + " motion transforms for " +
                  std::to_string(steps) + " motion steps");
    for (const glm::mat4& m : c.motion_world_to_camera)
      if (!finite(m) || std::abs(glm::determinant(glm::mat3(m))) < 1e-12f)
        throw Error("a camera motion transform is degenerate or not finite");
  }
  if (!scene.shutter_curve.empty()) {
    double sum = 0.0;
    for (float v : scene.shutter_curve) {
      if (!(v >= 0.0f) || !std::isfinite(v)) throw Error("the shutter curve must be finite and not negative");
      sum += v;
    }
    if (scene.shutter_curve.size() < 2 || scene.shutter_curve.size() > kMaxShutterCurve || !(sum > 0.0))
      throw Error("the shutter curve needs 2 to " + std::to_string(kMaxShutterCurve) +
                  " samples, not all zero");
  }
  if (!(s.dof_dice_factor >= 0) || !std::isfinite(s.dof_dice_factor))
    throw Error("defocus dicing factor must be a finite number >= 0");
  if (!(s.sample_memory_mib >= 1.0f) || !std::isfinite(s.sample_memory_mib))
    throw Error("the sample memory must be a finite number of MiB, at least 1");

  // Each program's source is read once for the values it needs.
  std::vector<size_t> needs;
  for (const MaterialProgram& p : scene.material_programs) needs.push_back(program_param_count(p.source));
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    if (!finite(m.color) || !finite(m.opacity) || !finite(m.specular_color) || !finite(m.emission) ||
        !std::isfinite(m.ka + m.kd + m.ks + m.roughness + m.metallic + m.specular))
      fail("material", m.name.empty() ? std::to_string(i) : m.name, "has NaN or infinite values");
    if (m.program < -1 || m.program >= static_cast<int>(scene.material_programs.size()))
      fail("material", m.name.empty() ? std::to_string(i) : m.name,
           "refers to material program " + std::to_string(m.program) + " of " +
               std::to_string(scene.material_programs.size()));
    if (!std::isfinite(m.displacement_bound) || m.displacement_bound < 0)
      fail("material", m.name.empty() ? std::to_string(i) : m.name, "needs a finite, non-negative displacement bound");
    if (m.program >= 0)
      check_program_params(m.program_params, needs[size_t(m.program)],
                           "material '" + (m.name.empty() ? std::to_string(i) : m.name) + "'");
  }
  const World& w = scene.world;
  if (w.program >= 0 && size_t(w.program) >= scene.material_programs.size())
    throw Error("world: program " + std::to_string(w.program) + " does not exist");
  if (w.program >= 0) check_program_params(w.program_params, needs[size_t(w.program)], "world");
  if (w.program >= 0 && (w.bake_width < 8 || w.bake_width > 8192))
    throw Error("world: the baked map's width must be 8 to 8192 texels, not " + std::to_string(w.bake_width));
  if (w.width < 0 || w.height < 0 || w.radiance.size() != size_t(w.width) * size_t(w.height) * 4)
    throw Error("world: the radiance map's size does not match its width and height");
  for (float v : w.radiance)
    if (!std::isfinite(v)) throw Error("world: the radiance map holds a NaN or infinite value");
  // Ray Visibility as a fraction of the light (RIB's reader takes the same range).
  if (!(w.diffuse >= 0.0f && w.diffuse <= 1.0f && w.glossy >= 0.0f && w.glossy <= 1.0f))
    throw Error("world: its diffuse and glossy visibility must be in [0, 1]");
  if (scene.settings.world_probes < 0 || scene.settings.world_probes > 64)
    throw Error("world: world_probes must be 0 to 64, not " + std::to_string(scene.settings.world_probes));
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (!finite(l.color) || !finite(l.position) || !finite(l.direction) || !std::isfinite(l.intensity) ||
        !std::isfinite(l.cone_angle + l.cone_delta_angle + l.beam_distribution) || !finite(l.axis_u) ||
        !std::isfinite(l.size_u + l.size_v) || l.size_u < 0 || l.size_v < 0)
      fail("light", std::to_string(i), "has NaN or infinite values");
    if (!(l.radius >= 0) || !std::isfinite(l.radius))
      fail("light", std::to_string(i), "needs a finite, non-negative radius");
    if (!(l.angle >= 0) || !(l.angle <= 3.14159266f))
      fail("light", std::to_string(i), "needs an angle between 0 and pi");
  }
  for (const Mesh& m : scene.meshes) {
    validate_mesh(m, scene.materials.size());
    validate_mesh_motion(m, size_t(scene.motion_steps));
  }
  for (const Image& im : scene.images) {
    if (im.width <= 0 || im.height <= 0 || im.pixels.size() != size_t(im.width) * size_t(im.height))
      fail("image", im.name, "needs width * height pixels");
    for (const glm::vec4& p : im.pixels)
      if (!finite(p)) fail("image", im.name, "has NaN or infinite pixels");
  }
  for (const BezierPatches& b : scene.bezier_patches) {
    validate_patches(b, scene.materials.size());
    validate_patches_motion(b, size_t(scene.motion_steps));
  }
  validate_instances(scene);
}

}  // namespace mp
