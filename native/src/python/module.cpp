// micropoly._native: builds a Scene from numpy arrays and renders it.
// Every C++ error surfaces as micropoly._native.Error (a RuntimeError).
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "micropoly/settings_util.h"
#include "rib/rib_reader.h"
#include "scene/curves.h"
#include "scene/points.h"

namespace py = pybind11;
using namespace mp;

// Bindings kept in files of their own (native/src/python/bind_*.cpp).
void bind_rib(py::module_& m);
void bind_sky(py::module_& m);

namespace {

template <typename T>
using Array = py::array_t<T, py::array::c_style | py::array::forcecast>;

std::vector<glm::vec3> to_points(const Array<float>& a, const char* what) {
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 3) throw Error(std::string(what) + " must be an (N, 3) array");
  std::vector<glm::vec3> out(static_cast<size_t>(a.shape(0)));
  std::memcpy(out.data(), a.data(), out.size() * sizeof(glm::vec3));
  return out;
}

// `count` RGBA values, non-finite ones read as zero (an Attribute node's
// value where a custom property holds NaN).
std::vector<glm::vec4> to_rgba(const float* v, size_t count) {
  std::vector<glm::vec4> out(count);
  for (size_t k = 0; k < 4 * count; ++k) out[k / 4][int(k % 4)] = std::isfinite(v[k]) ? v[k] : 0.0f;
  return out;
}

// Object Info's values and the Attribute nodes' RGBA per slot of one object
// (`what` names it in messages): object_color RGBA, attributes a multiple of 4.
// Moves surface `index` of `list` (negative: from the end) into a new
// prototype's `member`; returns the prototype's index.
template <typename Surface>
size_t to_prototype(Scene& s, std::vector<Surface>& list, std::vector<Surface> Prototype::*member, int index,
                    const std::string& name, const char* missing) {
  const int n = int(list.size());
  if (index < -n || index >= n) throw Error(missing + std::to_string(index));
  const auto at = list.begin() + (index < 0 ? index + n : index);
  Prototype p;
  p.name = name.empty() ? at->name : name;
  (p.*member).push_back(std::move(*at));
  list.erase(at);
  s.prototypes.push_back(std::move(p));
  return s.prototypes.size() - 1;
}

ObjectInfo to_object_info(const std::string& what, const std::vector<float>& object_color, float pass_index,
                          float random, const Array<float>& attributes) {
  if (object_color.size() != 4) throw Error(what + ": object_color must have 4 values (RGBA)");
  if (attributes.size() % 4 != 0) throw Error(what + ": attributes must be RGBA per slot");
  ObjectInfo info;
  info.color = glm::vec4(object_color[0], object_color[1], object_color[2], object_color[3]);
  info.pass_index = pass_index;
  info.random = random;
  info.attributes = to_rgba(attributes.data(), size_t(attributes.size()) / 4);
  return info;
}

template <typename T>
std::vector<T> to_vector(const Array<T>& a) {
  return std::vector<T>(a.data(), a.data() + a.size());
}

// Row-major 4x4 (numpy, Blender's Matrix) to GLM's column-major matrix.
glm::mat4 to_matrix(const Array<float>& a, const char* what) {
  if (a.size() == 0) return glm::mat4(1.0f);
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) throw Error(std::string(what) + " must be a (4, 4) array");
  glm::mat4 m;
  auto r = a.unchecked<2>();
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m[col][row] = r(row, col);
  return m;
}

// (steps, 4, 4) row-major matrices, one per motion step.
std::vector<glm::mat4> to_matrices(const Array<float>& a, const char* what) {
  if (a.size() == 0) return {};
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4) throw Error(std::string(what) + " must be a (steps, 4, 4) array");
  std::vector<glm::mat4> out(size_t(a.shape(0)));
  auto r = a.unchecked<3>();
  for (size_t k = 0; k < out.size(); ++k)
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) out[k][col][row] = r(py::ssize_t(k), row, col);
  return out;
}

// (steps, N, 3) points, one set per motion step; `owner` names the object
// in the error.
std::vector<std::vector<glm::vec3>> to_motion_points(const Array<float>& a, const std::string& owner) {
  std::vector<std::vector<glm::vec3>> out;
  if (a.size() == 0) return out;
  if (a.ndim() != 3 || a.shape(2) != 3) throw Error(owner + ": motion points must be a (steps, points, 3) array");
  const size_t count = size_t(a.shape(1));
  for (py::ssize_t k = 0; k < a.shape(0); ++k) {
    std::vector<glm::vec3> step(count);
    std::memcpy(step.data(), a.data() + size_t(k) * count * 3, count * sizeof(glm::vec3));
    out.push_back(std::move(step));
  }
  return out;
}

glm::vec3 to_vec3(const std::vector<float>& v, const char* what) {
  if (v.size() != 3) throw Error(std::string(what) + " needs 3 values");
  return {v[0], v[1], v[2]};
}

py::dict stats_dict(const RenderStats& s) {
  py::dict d, t;
  d["device"] = s.device;
  d["resolver"] = s.resolver;
  d["sampler"] = s.sampler;
  d["width"] = s.width;
  d["height"] = s.height;
  d["spp"] = s.spp;
  d["patches"] = s.patches;
  d["subpatches_diced"] = s.subpatches_diced;
  d["micropolygons"] = s.micropolygons;
  d["micropolygons_sampled"] = s.micropolygons_sampled;
  d["sample_tests"] = s.sample_tests;
  d["sampled_area_px"] = s.sampled_area_px;
  d["subpatches_occluded"] = s.subpatches_occluded;
  d["root_overlap"] = s.root_overlap;
  d["occlusion_waves"] = s.occlusion_waves;
  d["waves"] = s.waves;
  d["covered_pixels"] = s.covered_pixels;
  d["subpatches_unshaded"] = s.subpatches_unshaded;
  d["depth_complexity"] = s.covered_pixels ? s.sampled_area_px / double(s.covered_pixels) : 0.0;
  d["micropolygons_per_covered_pixel"] =
      s.covered_pixels ? double(s.micropolygons_sampled) / double(s.covered_pixels) : 0.0;
  d["bound_split_peak_bytes"] = s.bound_split_peak_bytes;
  d["instances"] = s.instances;
  d["scene_bytes"] = s.scene_bytes;
  d["bound_split_launches"] = s.bound_split_launches;
  d["batches"] = s.batches;
  auto by_phase = [](const std::vector<std::pair<std::string, size_t>>& counts) {
    py::dict out;
    for (const auto& [phase, count] : counts) out[py::str(phase)] = count;
    return out;
  };
  d["host_waits"] = s.host_waits;
  d["host_waits_by_phase"] = by_phase(s.host_waits_by_phase);
  d["kernel_launches"] = s.kernel_launches;
  d["kernel_launches_by_phase"] = by_phase(s.kernel_launches_by_phase);
  d["buckets"] = s.buckets;
  d["program_build_ms"] = s.program_build_ms;
  d["program_cache_hit"] = s.program_cache_hit;
  d["cancelled"] = s.cancelled;
  d["scene_reused"] = s.scene_reused;
  py::dict sh;
  sh["lights"] = s.shadows.lights;
  sh["level_bias"] = s.shadows.level_bias;
  sh["views"] = s.shadows.views;
  sh["pages_requested"] = s.shadows.pages_requested;
  sh["pages_rendered"] = s.shadows.pages_rendered;
  sh["pages_missing"] = s.shadows.pages_missing;
  sh["micropolygons"] = s.shadows.micropolygons;
  sh["subpatches_occluded"] = s.shadows.subpatches_occluded;
  sh["marking_passes"] = s.shadows.marking_passes;
  sh["marking_occluded"] = s.shadows.marking_occluded;
  sh["budget_bytes"] = s.shadows.budget_bytes;
  sh["peak_bytes"] = s.shadows.peak_bytes;
  sh["batches"] = s.shadows.batches;
  sh["mark_wall_ms"] = s.shadows.mark_wall_ms;
  sh["render_wall_ms"] = s.shadows.render_wall_ms;
  py::list per_light;
  for (const ShadowLightStats& l : s.shadows.per_light) {
    py::dict e;
    e["light"] = l.light;
    e["pages"] = l.pages;
    e["bytes"] = l.bytes;
    per_light.append(e);
  }
  sh["per_light"] = per_light;
  d["shadows"] = sh;
  t["upload"] = s.timings_ms.upload;
  t["bound_split"] = s.timings_ms.bound_split;
  t["dice"] = s.timings_ms.dice;
  t["shade"] = s.timings_ms.shade;
  t["sample"] = s.timings_ms.sample;
  t["resolve"] = s.timings_ms.resolve;
  t["readback"] = s.timings_ms.readback;
  t["readback_wait"] = s.timings_ms.readback_wait;
  t["shadow_mark"] = s.timings_ms.shadow_mark;
  t["shadow"] = s.timings_ms.shadow;
  t["shadow_bound_split"] = s.timings_ms.shadow_bound_split;
  t["shadow_dice"] = s.timings_ms.shadow_dice;
  t["shadow_sample"] = s.timings_ms.shadow_sample;
  t["shadows_wall"] = s.timings_ms.shadows_wall;
  t["occlusion"] = s.timings_ms.occlusion;
  t["total"] = s.timings_ms.total;
  d["timings_ms"] = t;
  return d;
}

py::dict result_dict(RenderResult&& r) {
  py::dict d;
  auto h = static_cast<py::ssize_t>(r.height), w = static_cast<py::ssize_t>(r.width);
  if (r.rgba.size() != static_cast<size_t>(h * w * 4)) h = w = 0;  // no pixels: cancelled, or ReadBack::None
  d["rgba"] = Array<float>({h, w, py::ssize_t(4)}, r.rgba.data());
  if (!r.depth.empty()) d["depth"] = Array<float>({h, w}, r.depth.data());
  if (!r.normal.empty()) d["normal"] = Array<float>({h, w, py::ssize_t(3)}, r.normal.data());
  d["stats"] = stats_dict(r.stats);
  return d;
}

}  // namespace

PYBIND11_MODULE(_native, m) {
  m.doc() = "Micropoly native renderer";
  m.attr("__version__") = MICROPOLY_VERSION;
  py::register_exception<Error>(m, "Error", PyExc_RuntimeError);

  py::enum_<PixelFilter>(m, "PixelFilter")
      .value("BOX", PixelFilter::Box)
      .value("GAUSSIAN", PixelFilter::Gaussian)
      .value("TRIANGLE", PixelFilter::Triangle)
      .value("BLACKMAN_HARRIS", PixelFilter::BlackmanHarris);
  py::enum_<BoundSplitMethod>(m, "BoundSplitMethod")
      .value("BOUNDED", BoundSplitMethod::Bounded)
      .value("BREADTH", BoundSplitMethod::Breadth);
  py::enum_<Sampler>(m, "Sampler")
      .value("AUTO", Sampler::Auto)
      .value("TILES", Sampler::Tiles)
      .value("MICROPOLYGONS", Sampler::Micropolygons)
      .value("BINS", Sampler::Bins);
  py::enum_<Resolver>(m, "Resolver")
      .value("AUTO", Resolver::Auto)
      .value("TILES", Resolver::Tiles)
      .value("PIXELS", Resolver::Pixels);
  py::enum_<OcclusionWaves>(m, "OcclusionWaves")
      .value("AUTO", OcclusionWaves::Auto)
      .value("ON", OcclusionWaves::On)
      .value("OFF", OcclusionWaves::Off);
  py::enum_<ReadBack>(m, "ReadBack")
      .value("FLOAT", ReadBack::Float)
      .value("HALF", ReadBack::Half)
      .value("NONE", ReadBack::None);
  py::enum_<VisibilityFirst>(m, "VisibilityFirst")
      .value("AUTO", VisibilityFirst::Auto)
      .value("ON", VisibilityFirst::On)
      .value("OFF", VisibilityFirst::Off);

  py::class_<RenderSettings>(m, "RenderSettings")
      .def(py::init<>())
      .def_readwrite("width", &RenderSettings::width)
      .def_readwrite("height", &RenderSettings::height)
      .def_readwrite("pixel_aspect", &RenderSettings::pixel_aspect)
      .def_readwrite("crop_x0", &RenderSettings::crop_x0)
      .def_readwrite("crop_x1", &RenderSettings::crop_x1)
      .def_readwrite("crop_y0", &RenderSettings::crop_y0)
      .def_readwrite("crop_y1", &RenderSettings::crop_y1)
      .def_readwrite("samples_x", &RenderSettings::samples_x)
      .def_readwrite("samples_y", &RenderSettings::samples_y)
      .def_property(
          "samples", [](const RenderSettings& s) { return s.samples_x * s.samples_y; },
          [](RenderSettings& s, int n) { set_samples_per_pixel(s, n); })
      .def_readwrite("shading_rate", &RenderSettings::shading_rate)
      .def_readwrite("filter", &RenderSettings::filter)
      .def_readwrite("filter_width", &RenderSettings::filter_width)
      .def_readwrite("bound_split", &RenderSettings::bound_split)
      .def_readwrite("bound_split_memory_mib", &RenderSettings::bound_split_memory_mib)
      .def_readwrite("max_grid_size", &RenderSettings::max_grid_size)
      .def_readwrite("max_split_depth", &RenderSettings::max_split_depth)
      .def_readwrite("backface_culling", &RenderSettings::backface_culling)
      .def_readwrite("depth_and_normal_passes", &RenderSettings::depth_and_normal_passes)
      .def_readwrite("normal_pass", &RenderSettings::normal_pass)
      .def_readwrite("shadows", &RenderSettings::shadows)
      .def_readwrite("shadow_memory_mib", &RenderSettings::shadow_memory_mib)
      .def_readwrite("shadow_shading_rate", &RenderSettings::shadow_shading_rate)
      .def_readwrite("keep_shadow_pages", &RenderSettings::keep_shadow_pages)
      .def_readwrite("soft_shadow_pages", &RenderSettings::soft_shadow_pages)
      .def_readwrite("occlusion_culling", &RenderSettings::occlusion_culling)
      .def_readwrite("sample_culling", &RenderSettings::sample_culling)
      .def_readwrite("holdout_covers", &RenderSettings::holdout_covers)
      .def_readwrite("world_probes", &RenderSettings::world_probes)
      .def_readwrite("texture_filter_width", &RenderSettings::texture_filter_width)
      .def_readwrite("dof_dice_factor", &RenderSettings::dof_dice_factor)
      .def_readwrite("sampler", &RenderSettings::sampler)
      .def_readwrite("resolver", &RenderSettings::resolver)
      .def_readwrite("bound_split_chain", &RenderSettings::bound_split_chain)
      .def_readwrite("bound_split_steps", &RenderSettings::bound_split_steps)
      .def_readwrite("visibility_first", &RenderSettings::visibility_first)
      .def_readwrite("occlusion_waves", &RenderSettings::occlusion_waves)
      .def_readwrite("read_back", &RenderSettings::read_back)
      .def_readwrite("sample_memory_mib", &RenderSettings::sample_memory_mib);

  py::class_<Scene>(m, "Scene")
      .def(py::init<>())
      .def_readwrite("settings", &Scene::settings)
      .def(
          "set_camera",
          [](Scene& s, const Array<float>& world_to_camera, bool ortho, float fov_degrees, float clip_near, float clip_far,
             std::vector<float> screen_window) {
            s.camera.world_to_camera = to_matrix(world_to_camera, "world_to_camera");
            s.camera.projection = ortho ? Camera::Projection::Orthographic : Camera::Projection::Perspective;
            s.camera.fov_degrees = fov_degrees;
            s.camera.clip_near = clip_near;
            s.camera.clip_far = clip_far;
            if (!screen_window.empty()) {
              if (screen_window.size() != 4) throw Error("screen_window needs (left, right, bottom, top)");
              s.camera.screen_left = screen_window[0], s.camera.screen_right = screen_window[1];
              s.camera.screen_bottom = screen_window[2], s.camera.screen_top = screen_window[3];
            }
          },
          py::arg("world_to_camera"), py::arg("orthographic") = false, py::arg("fov_degrees") = 90.0f,
          py::arg("clip_near") = 0.01f, py::arg("clip_far") = 1e30f, py::arg("screen_window") = std::vector<float>{},
          "Camera looking down -Z of its space (Blender's convention); world_to_camera is row-major.")
      .def(
          "set_motion",
          [](Scene& s, int steps, const Array<float>& camera_world_to_camera, const Array<float>& shutter_curve) {
            s.motion_steps = steps;
            s.camera.motion_world_to_camera = to_matrices(camera_world_to_camera, "camera_world_to_camera");
            s.shutter_curve = to_vector(shutter_curve);
          },
          py::arg("steps"), py::arg("camera_world_to_camera") = Array<float>(),
          py::arg("shutter_curve") = Array<float>(),
          "Motion blur: `steps` (0, or 2 and more) times evenly spread over the shutter, the camera's "
          "world-to-camera matrix at each (row-major (steps, 4, 4)), or none where it does not move, and how "
          "open the shutter is over its time (samples evenly spread; none: fully open).")
      .def(
          "set_mesh_motion",
          [](Scene& s, int index, const Array<float>& points, const Array<float>& object_to_world) {
            const int n = int(s.meshes.size());
            if (index < -n || index >= n) throw Error("set_mesh_motion: no mesh " + std::to_string(index));
            Mesh& m = s.meshes[size_t(index < 0 ? index + n : index)];
            m.motion_object_to_world = to_matrices(object_to_world, "object_to_world");
            m.motion_points = to_motion_points(points, "mesh '" + m.name + "'");
          },
          py::arg("index"), py::arg("points") = Array<float>(), py::arg("object_to_world") = Array<float>(),
          "Motion of mesh `index` (negative: from the end): its points (steps, N, 3) where it deforms, its "
          "object-to-world matrices (steps, 4, 4) where it moves; empty for what stays.")
      .def(
          "set_depth_of_field",
          [](Scene& s, float lens_radius, float focus_distance, int blades, float rotation, float ratio) {
            s.camera.lens_radius = lens_radius;
            s.camera.focus_distance = focus_distance;
            s.camera.aperture_blades = blades;
            s.camera.aperture_rotation = rotation;
            s.camera.aperture_ratio = ratio;
          },
          py::arg("lens_radius"), py::arg("focus_distance"), py::arg("blades") = 0, py::arg("rotation") = 0.0f,
          py::arg("ratio") = 1.0f,
          "Thin-lens depth of field: aperture radius (scene units; 0 turns it off), distance in focus along the "
          "view axis, aperture polygon (blades < 3: round), its rotation (radians) and anamorphic ratio, as Cycles.")
      .def(
          "add_material",
          [](Scene& s, const std::string& name, const std::string& model, std::vector<float> color,
             std::vector<float> opacity, float ka, float kd, float ks, float roughness, std::vector<float> specular_color,
             std::vector<float> emission, float metallic, float specular, int program, bool program_displaces,
             bool program_shades, float displacement_bound, bool displacement_bound_world, bool program_alpha,
             bool layered, bool retro_diffuse, bool multiscatter, std::vector<float> program_params,
             bool program_alpha_cut) {
            Material mat;
            mat.program_params = std::move(program_params);
            mat.layered = layered;
            mat.retro_diffuse = retro_diffuse;
            mat.multiscatter = multiscatter;
            mat.program_alpha = program_alpha;
            mat.program_alpha_cut = program_alpha && program_alpha_cut;
            mat.displacement_bound_world = displacement_bound_world;
            mat.program = program;
            mat.program_displaces = program_displaces;
            mat.program_shades = program_shades;
            mat.displacement_bound = displacement_bound;
            mat.name = name;
            if (model == "constant") mat.model = Material::Model::Constant;
            else if (model == "matte") mat.model = Material::Model::Matte;
            else if (model == "plastic") mat.model = Material::Model::Plastic;
            else if (model == "principled") mat.model = Material::Model::Principled;
            else throw Error("unknown material model '" + model + "' (constant, matte, plastic, principled)");
            mat.color = to_vec3(color, "color");
            mat.opacity = to_vec3(opacity, "opacity");
            mat.ka = ka, mat.kd = kd, mat.ks = ks, mat.roughness = roughness;
            mat.specular_color = to_vec3(specular_color, "specular_color");
            mat.emission = to_vec3(emission, "emission");
            mat.metallic = metallic;
            mat.specular = specular;
            s.materials.push_back(mat);
            return s.materials.size() - 1;
          },
          py::arg("name") = "", py::arg("model") = "plastic", py::arg("color") = std::vector<float>{1, 1, 1},
          py::arg("opacity") = std::vector<float>{1, 1, 1}, py::arg("ka") = 1.0f, py::arg("kd") = 0.5f,
          py::arg("ks") = 0.5f, py::arg("roughness") = 0.1f, py::arg("specular_color") = std::vector<float>{1, 1, 1},
          py::arg("emission") = std::vector<float>{0, 0, 0}, py::arg("metallic") = 0.0f, py::arg("specular") = 0.5f,
          py::arg("program") = -1, py::arg("program_displaces") = false, py::arg("program_shades") = false,
          py::arg("displacement_bound") = 0.0f, py::arg("displacement_bound_world") = false,
          py::arg("program_alpha") = false, py::arg("layered") = false, py::arg("retro_diffuse") = false, py::arg("multiscatter") = false,
          py::arg("program_params") = std::vector<float>{}, py::arg("program_alpha_cut") = false,
          "Adds a material (constant, matte, plastic or principled; see scene.h); returns its index. "
          "program_params are its program's node values (Material::program_params).")
      .def(
          "add_material_program",
          [](Scene& s, const std::string& name, const std::string& source) {
            s.material_programs.push_back(MaterialProgram{name, source});
            return s.material_programs.size() - 1;
          },
          py::arg("name"), py::arg("source"),
          "Adds a node tree translated to OpenCL C (kernels/materials/material_program.cl); returns its index.")
      .def(
          "add_light",
          [](Scene& s, const std::string& type, std::vector<float> color, float intensity, std::vector<float> position,
             std::vector<float> direction, float cone_angle, float cone_delta_angle, float beam_distribution,
             const std::string& shape, std::vector<float> axis_u, float size_u, float size_v, bool cast_shadows,
             float radius, bool soft_falloff, float angle) {
            Light l;
            l.cast_shadows = cast_shadows;
            l.radius = radius;
            l.soft_falloff = soft_falloff;
            l.angle = angle;
            if (type == "ambient") l.type = Light::Type::Ambient;
            else if (type == "distant") l.type = Light::Type::Distant;
            else if (type == "point") l.type = Light::Type::Point;
            else if (type == "spot") l.type = Light::Type::Spot;
            else if (type == "area") l.type = Light::Type::Area;
            else throw Error("unknown light type '" + type + "' (ambient, distant, point, spot, area)");
            if (shape == "rectangle") l.shape = Light::Shape::Rectangle;
            else if (shape == "ellipse") l.shape = Light::Shape::Ellipse;
            else throw Error("unknown area light shape '" + shape + "' (rectangle, ellipse)");
            l.axis_u = to_vec3(axis_u, "axis_u");
            l.size_u = size_u, l.size_v = size_v;
            l.color = to_vec3(color, "color");
            l.intensity = intensity;
            l.position = to_vec3(position, "position");
            l.direction = to_vec3(direction, "direction");
            l.cone_angle = cone_angle, l.cone_delta_angle = cone_delta_angle, l.beam_distribution = beam_distribution;
            s.lights.push_back(l);
          },
          py::arg("type"), py::arg("color") = std::vector<float>{1, 1, 1}, py::arg("intensity") = 1.0f,
          py::arg("position") = std::vector<float>{0, 0, 0}, py::arg("direction") = std::vector<float>{0, 0, -1},
          py::arg("cone_angle") = 0.5235988f, py::arg("cone_delta_angle") = 0.0872665f, py::arg("beam_distribution") = 2.0f,
          py::arg("shape") = "rectangle", py::arg("axis_u") = std::vector<float>{1, 0, 0}, py::arg("size_u") = 1.0f,
          py::arg("size_v") = 1.0f, py::arg("cast_shadows") = true, py::arg("radius") = 0.0f,
          py::arg("soft_falloff") = true, py::arg("angle") = 0.0f,
          "Adds a light in world space (units and shadows: scene.h).")
      .def(
          "add_mesh",
          [](Scene& s, const std::string& name, const Array<float>& points, const Array<int>& face_vertex_counts,
             const Array<int>& face_vertex_indices, bool subdivision, const Array<float>& object_to_world, int material,
             const Array<int>& face_materials, const Array<int>& crease_vertices, const Array<float>& crease_sharpness,
             const Array<int>& corner_vertices, const Array<float>& corner_sharpness, const Array<int>& hole_faces,
             const std::string& boundary, bool double_sided, std::vector<float> texspace_location,
             std::vector<float> texspace_size, const Array<float>& uv_layers, const Array<float>& corner_normals,
             bool visible_camera, bool cast_shadows, std::vector<float> object_color, float pass_index, float random,
             const Array<float>& attributes) {
            Mesh mesh;
            mesh.info = to_object_info("mesh '" + name + "'", object_color, pass_index, random, attributes);
            mesh.visible_camera = visible_camera;
            mesh.cast_shadows = cast_shadows;
            mesh.corner_normals = to_points(corner_normals, "corner_normals");
            if (uv_layers.size() > 0) {
              if (uv_layers.ndim() != 3 || uv_layers.shape(2) != 2)
                throw Error("mesh '" + name + "': uv_layers must be a (layers, face corners, 2) array");
              const auto per_layer = static_cast<size_t>(uv_layers.shape(1));
              for (py::ssize_t k = 0; k < uv_layers.shape(0); ++k) {
                std::vector<glm::vec2> layer(per_layer);
                std::memcpy(layer.data(), uv_layers.data(k, 0, 0), per_layer * sizeof(glm::vec2));
                mesh.uv_layers.push_back(std::move(layer));
              }
            }
            mesh.texspace_location = to_vec3(texspace_location, "texspace_location");
            mesh.texspace_size = to_vec3(texspace_size, "texspace_size");
            mesh.name = name;
            mesh.scheme = subdivision ? SubdivScheme::CatmullClark : SubdivScheme::None;
            mesh.points = to_points(points, "points");
            mesh.face_vertex_counts = to_vector(face_vertex_counts);
            mesh.face_vertex_indices = to_vector(face_vertex_indices);
            mesh.object_to_world = to_matrix(object_to_world, "object_to_world");
            mesh.material = material;
            mesh.face_materials = to_vector(face_materials);
            mesh.crease_vertices = to_vector(crease_vertices);
            mesh.crease_sharpness = to_vector(crease_sharpness);
            mesh.corner_vertices = to_vector(corner_vertices);
            mesh.corner_sharpness = to_vector(corner_sharpness);
            mesh.hole_faces = to_vector(hole_faces);
            if (boundary == "none") mesh.boundary = BoundaryInterpolation::None;
            else if (boundary == "edge_only") mesh.boundary = BoundaryInterpolation::EdgeOnly;
            else if (boundary == "edge_and_corner") mesh.boundary = BoundaryInterpolation::EdgeAndCorner;
            else throw Error("unknown boundary interpolation '" + boundary + "'");
            mesh.double_sided = double_sided;
            s.meshes.push_back(std::move(mesh));
          },
          py::arg("name"), py::arg("points"), py::arg("face_vertex_counts"), py::arg("face_vertex_indices"),
          py::arg("subdivision") = false, py::arg("object_to_world") = Array<float>(),
          py::arg("material") = 0, py::arg("face_materials") = Array<int>(), py::arg("crease_vertices") = Array<int>(),
          py::arg("crease_sharpness") = Array<float>(), py::arg("corner_vertices") = Array<int>(),
          py::arg("corner_sharpness") = Array<float>(), py::arg("hole_faces") = Array<int>(),
          py::arg("boundary") = "edge_and_corner", py::arg("double_sided") = true,
          py::arg("texspace_location") = std::vector<float>{0, 0, 0},
          py::arg("texspace_size") = std::vector<float>{0, 0, 0}, py::arg("uv_layers") = Array<float>(),
          py::arg("corner_normals") = Array<float>(), py::arg("visible_camera") = true, py::arg("cast_shadows") = true,
          py::arg("object_color") = std::vector<float>{1, 1, 1, 1}, py::arg("pass_index") = 0.0f,
          py::arg("random") = 0.0f, py::arg("attributes") = Array<float>(),
          "Adds a mesh; uv_layers is (layers, face corners, 2): UV layer k is what material programs read as "
          "UV layer k; corner_normals (face corners, 3), object space, shade a polygon mesh smooth; attributes "
          "(slots, 4): the RGBA that Attribute nodes of type Object or Instancer read in each slot.")
      .def(
          "add_image",
          [](Scene& s, const std::string& name, const Array<float>& pixels, bool srgb) {
            if (pixels.ndim() != 3 || pixels.shape(2) != 4)
              throw Error("image '" + name + "': pixels must be a (height, width, 4) array");
            Image im;
            im.name = name;
            im.srgb = srgb;
            im.height = static_cast<int>(pixels.shape(0));
            im.width = static_cast<int>(pixels.shape(1));
            im.pixels.resize(static_cast<size_t>(pixels.size() / 4));
            std::memcpy(im.pixels.data(), pixels.data(), im.pixels.size() * sizeof(glm::vec4));
            s.images.push_back(std::move(im));
            return s.images.size() - 1;
          },
          py::arg("name"), py::arg("pixels"), py::arg("srgb") = false,
          "Adds a texture image: (height, width, 4) RGBA, rows bottom to top, scene-linear or (srgb) sRGB-encoded "
          "colour decoded after filtering; returns its index.")
      .def(
          "set_world",
          [](Scene& s, int program, int bake_width, const Array<float>& radiance, bool camera, float diffuse,
             float glossy, bool cast_shadows, std::vector<float> program_params) {
            World w;
            w.program = program;
            w.program_params = std::move(program_params);
            w.bake_width = bake_width;
            if (radiance.size() > 0) {
              if (radiance.ndim() != 3 || radiance.shape(2) != 4)
                throw Error("world: radiance must be a (height, width, 4) array");
              w.height = static_cast<int>(radiance.shape(0));
              w.width = static_cast<int>(radiance.shape(1));
              w.radiance.assign(radiance.data(), radiance.data() + radiance.size());
            }
            w.camera = camera, w.diffuse = diffuse, w.glossy = glossy, w.cast_shadows = cast_shadows;
            s.world = std::move(w);
          },
          py::arg("program") = -1, py::arg("bake_width") = 512, py::arg("radiance") = Array<float>(),
          py::arg("camera") = true, py::arg("diffuse") = 1.0f, py::arg("glossy") = 1.0f, py::arg("cast_shadows") = true,
          py::arg("program_params") = std::vector<float>{},
          "Sets the world (scene.h, World): a world program's index (add_material_program) baked to a map "
          "bake_width wide, or an equirectangular radiance map (height, width, 4), rows bottom to top.")
      .def(
          "mesh_to_prototype",
          [](Scene& s, int index, const std::string& name) {
            return to_prototype(s, s.meshes, &Prototype::meshes, index, name, "mesh_to_prototype: no mesh ");
          },
          py::arg("index") = -1, py::arg("name") = "",
          "Moves mesh `index` (negative: from the end) out of the scene into a new prototype (scene.h), rendered "
          "only where instances place it; returns the prototype's index. Its object_to_world places it in the "
          "prototype's own space.")
      .def(
          "patch_set_to_prototype",
          [](Scene& s, int index, const std::string& name) {
            return to_prototype(s, s.bezier_patches, &Prototype::bezier_patches, index, name,
                                "patch_set_to_prototype: no patch set ");
          },
          py::arg("index") = -1, py::arg("name") = "",
          "As mesh_to_prototype, for patch set `index` (curves' tubes, quadrics' patches).")
      .def(
          "add_instances",
          [](Scene& s, int prototype, const Array<float>& object_to_world, const Array<float>& random,
             const Array<float>& object_color, const Array<float>& pass_index, bool visible_camera, bool cast_shadows,
             const Array<float>& motion_object_to_world, const Array<float>& attributes) {
            if (prototype < 0 || size_t(prototype) >= s.prototypes.size())
              throw Error("add_instances: no prototype " + std::to_string(prototype));
            const std::vector<glm::mat4> placed = to_matrices(object_to_world, "object_to_world");
            const size_t n = placed.size();
            auto per_instance = [&](const Array<float>& a, size_t width, const char* what) {
              if (a.size() != 0 && size_t(a.size()) != n * width)
                throw Error(std::string("add_instances: ") + what + " needs " + std::to_string(width) +
                            " value(s) per instance");
              return a.size() != 0;
            };
            const bool has_random = per_instance(random, 1, "random");
            const bool has_color = per_instance(object_color, 4, "object_color");
            const bool has_pass = per_instance(pass_index, 1, "pass_index");
            size_t slots = 0;
            if (attributes.size() != 0) {
              if (attributes.ndim() != 3 || size_t(attributes.shape(0)) != n || attributes.shape(2) != 4)
                throw Error("add_instances: attributes must be an (instances, slots, 4) array");
              slots = size_t(attributes.shape(1));
            }
            size_t steps = 0;
            if (motion_object_to_world.size() != 0) {
              if (motion_object_to_world.ndim() != 4 || size_t(motion_object_to_world.shape(0)) != n ||
                  motion_object_to_world.shape(2) != 4 || motion_object_to_world.shape(3) != 4)
                throw Error("add_instances: motion_object_to_world must be an (instances, steps, 4, 4) array");
              steps = size_t(motion_object_to_world.shape(1));
            }
            s.instances.reserve(s.instances.size() + n);
            for (size_t i = 0; i < n; ++i) {
              Instance inst;
              inst.prototype = prototype;
              inst.object_to_world = placed[i];
              if (has_random) inst.info.random = random.data()[i];
              if (has_color) {
                const float* c = object_color.data() + 4 * i;
                inst.info.color = glm::vec4(c[0], c[1], c[2], c[3]);
              }
              if (has_pass) inst.info.pass_index = pass_index.data()[i];
              if (slots) inst.info.attributes = to_rgba(attributes.data() + i * slots * 4, slots);
              inst.visible_camera = visible_camera;
              inst.cast_shadows = cast_shadows;
              for (size_t k = 0; k < steps; ++k) {
                const float* f = motion_object_to_world.data() + (i * steps + k) * 16;
                glm::mat4 m;
                for (int row = 0; row < 4; ++row)
                  for (int col = 0; col < 4; ++col) m[col][row] = f[4 * row + col];
                inst.motion_object_to_world.push_back(m);
              }
              s.instances.push_back(std::move(inst));
            }
          },
          py::arg("prototype"), py::arg("object_to_world"), py::arg("random") = Array<float>(),
          py::arg("object_color") = Array<float>(), py::arg("pass_index") = Array<float>(),
          py::arg("visible_camera") = true, py::arg("cast_shadows") = true,
          py::arg("motion_object_to_world") = Array<float>(), py::arg("attributes") = Array<float>(),
          "Places `prototype` once per row-major matrix of object_to_world (instances, 4, 4); per instance, "
          "optionally: Object Info's random (instances,), object_color (instances, 4), pass_index (instances,), "
          "motion_object_to_world (instances, steps, 4, 4) and the RGBA Attribute nodes of type Object or "
          "Instancer read in each slot: attributes (instances, slots, 4).")
      .def(
          "add_curves",
          [](Scene& s, const std::string& name, const Array<float>& points, const Array<float>& radii,
             const Array<int>& offsets, const Array<float>& object_to_world, int material, bool visible_camera,
             bool cast_shadows, std::vector<float> object_color, float pass_index, float random,
             const Array<float>& attributes, const Array<float>& motion_points,
             const Array<float>& motion_object_to_world, const Array<float>& point_layers, bool ribbons) {
            CurveSet curves;
            curves.ribbons = ribbons;
            curves.name = name;
            curves.points = to_points(points, "points");
            if (radii.ndim() != 1) throw Error("curves '" + name + "': radii must be a (points,) array");
            curves.radii.assign(radii.data(), radii.data() + radii.size());
            if (offsets.ndim() != 1) throw Error("curves '" + name + "': offsets must be a (curves + 1,) array");
            curves.offsets.assign(offsets.data(), offsets.data() + offsets.size());
            curves.object_to_world = to_matrix(object_to_world, "object_to_world");
            curves.material = material;
            curves.visible_camera = visible_camera;
            curves.cast_shadows = cast_shadows;
            curves.info = to_object_info("curves '" + name + "'", object_color, pass_index, random, attributes);
            curves.motion_object_to_world = to_matrices(motion_object_to_world, "motion_object_to_world");
            curves.motion_points = to_motion_points(motion_points, "curves '" + name + "'");
            if (point_layers.size() > 0) {
              if (point_layers.ndim() != 3 || point_layers.shape(2) != 2)
                throw Error("curves '" + name + "': point_layers must be a (layers, points, 2) array");
              for (py::ssize_t k = 0; k < point_layers.shape(0); ++k) {
                const auto* first = reinterpret_cast<const glm::vec2*>(point_layers.data(k, 0, 0));
                curves.point_layers.emplace_back(first, first + point_layers.shape(1));
              }
            }
            return add_curves(s, curves);
          },
          py::arg("name"), py::arg("points"), py::arg("radii"), py::arg("offsets"),
          py::arg("object_to_world") = Array<float>(), py::arg("material") = 0, py::arg("visible_camera") = true,
          py::arg("cast_shadows") = true, py::arg("object_color") = std::vector<float>{1, 1, 1, 1},
          py::arg("pass_index") = 0.0f, py::arg("random") = 0.0f, py::arg("attributes") = Array<float>(),
          py::arg("motion_points") = Array<float>(), py::arg("motion_object_to_world") = Array<float>(),
          py::arg("point_layers") = Array<float>(), py::arg("ribbons") = false,
          "Adds curves (Catmull-Rom keys: points (points, 3), radii (points,), object space; curve c has the "
          "points [offsets[c], offsets[c + 1])) as round tubes of Bezier patches (scene/curves.h), or with "
          "ribbons=True as ribbons facing each view (Cycles' Rounded Ribbons), with their "
          "motion where they move: the points at each motion step (steps, points, 3) and the object-to-world "
          "matrices (steps, 4, 4). point_layers (layers, points, 2): what material programs read as UV layer "
          "k, one value per point, linear along the curve. Returns how many curves were skipped (fewer than 2 points, or a point or "
          "radius not finite, a radius below 0).")
      .def(
          "add_points",
          [](Scene& s, const std::string& name, const Array<float>& positions, const Array<float>& radii,
             const Array<float>& object_to_world, int material, bool visible_camera, bool cast_shadows,
             std::vector<float> object_color, float pass_index, float random, const Array<float>& attributes,
             const Array<float>& point_attributes, const Array<float>& motion_points,
             const Array<float>& motion_object_to_world) {
            PointCloud cloud;
            cloud.name = name;
            cloud.positions = to_points(positions, "positions");
            if (radii.ndim() != 1) throw Error("point cloud '" + name + "': radii must be a (points,) array");
            cloud.radii.assign(radii.data(), radii.data() + radii.size());
            cloud.object_to_world = to_matrix(object_to_world, "object_to_world");
            cloud.material = material;
            cloud.visible_camera = visible_camera;
            cloud.cast_shadows = cast_shadows;
            cloud.info = to_object_info("point cloud '" + name + "'", object_color, pass_index, random, attributes);
            if (point_attributes.size() > 0) {
              if (point_attributes.ndim() != 3 || point_attributes.shape(2) != 4)
                throw Error("point cloud '" + name + "': point_attributes must be a (points, slots, 4) array");
              for (py::ssize_t i = 0; i < point_attributes.shape(0); ++i) {
                const auto* first = reinterpret_cast<const glm::vec4*>(point_attributes.data(i, 0, 0));
                cloud.point_attributes.emplace_back(first, first + point_attributes.shape(1));
              }
            }
            cloud.motion_positions = to_motion_points(motion_points, "point cloud '" + name + "'");
            cloud.motion_object_to_world = to_matrices(motion_object_to_world, "motion_object_to_world");
            return add_point_cloud(s, cloud);
          },
          py::arg("name"), py::arg("positions"), py::arg("radii"), py::arg("object_to_world") = Array<float>(),
          py::arg("material") = 0, py::arg("visible_camera") = true, py::arg("cast_shadows") = true,
          py::arg("object_color") = std::vector<float>{1, 1, 1, 1}, py::arg("pass_index") = 0.0f,
          py::arg("random") = 0.0f, py::arg("attributes") = Array<float>(),
          py::arg("point_attributes") = Array<float>(), py::arg("motion_points") = Array<float>(),
          py::arg("motion_object_to_world") = Array<float>(),
          "Adds a point cloud (positions (points, 3) and radii (points,), object space) as spheres, Cycles' "
          "shape for points: one instance of a shared unit sphere per point (scene/points.h), each reading the "
          "cloud's Object Info and attributes (slots, 4), or its own attributes (points, slots, 4); with motion "
          "blur, the positions (steps, points, 3) and transforms (steps, 4, 4) at each step move them. Returns how many points were skipped (a position or "
          "radius not finite, a radius not positive).")
      .def("validate", [](const Scene& s) { validate_scene(s); })
      .def_property_readonly("prototype_count", [](const Scene& s) { return s.prototypes.size(); })
      .def_property_readonly("instance_count", [](const Scene& s) { return s.instances.size(); })
      .def_property_readonly("mesh_count", [](const Scene& s) { return s.meshes.size(); })
      .def_property_readonly("patch_set_count", [](const Scene& s) { return s.bezier_patches.size(); })
      .def_property_readonly("material_count", [](const Scene& s) { return s.materials.size(); })
      .def_property_readonly("light_count", [](const Scene& s) { return s.lights.size(); });

  bind_rib(m);
  bind_sky(m);

  m.def("list_devices", [] {
    std::vector<DeviceInfo> devices;
    {
      // The first call starts the OpenCL drivers (tens of milliseconds):
      // other Python threads run meanwhile.
      py::gil_scoped_release release;
      devices = list_devices();
    }
    py::list out;
    for (auto& d : devices) {
      py::dict e;
      e["index"] = d.index;
      e["name"] = d.name;
      e["platform"] = d.platform;
      e["type"] = d.type;
      e["version"] = d.version;
      out.append(e);
    }
    return out;
  });

  py::class_<Renderer>(m, "Renderer")
      .def(py::init<const std::string&>(), py::arg("device") = "", py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("device", [](const Renderer& r) { return r.device().name; })
      .def(
          "render",
          [](Renderer& r, const Scene& scene, py::object progress) {
            ProgressCallback cb;
            if (!progress.is_none()) {
              cb = [progress](float p) {
                py::gil_scoped_acquire gil;
                py::object ret = progress(p);
                return ret.is_none() || ret.cast<bool>();
              };
            }
            RenderResult result;
            {
              py::gil_scoped_release release;
              result = r.render(scene, cb);
            }
            return result_dict(std::move(result));
          },
          py::arg("scene"), py::arg("progress") = py::none(),
          "Renders the scene; returns dict(rgba=(H,W,4), depth=(H,W), normal=(H,W,3), stats=dict). Rows top first. "
          "progress(p) may return False to cancel.");
}
