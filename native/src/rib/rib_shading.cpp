// Surfaces, colors and light sources, following the standard RenderMan
// shaders (RI spec 3.2, appendix A): constant, matte, plastic; ambientlight,
// distantlight, pointlight, spotlight, with their parameter defaults. Two
// Micropoly shader names map to the Scene's own models:
// "micropoly_principled" (Material::Model::Principled) and
// "micropoly_arealight" (Light::Type::Area); every surface also takes
// "color emission". Lights cast shadows as RenderMan's shadow-casting lights
// do: when they name a shadow map ("string shadowname"); their size for soft
// shadows is a Micropoly extension ("micropoly:radius", "micropoly:angle").
// See docs/rib.md.
#include <cfloat>
#include <cmath>
#include <functional>
#include <initializer_list>

#include <glm/gtc/constants.hpp>

#include "rib/rib_parser.h"

namespace mp::rib {
namespace {

void warn_unknown_params(const ParamList& params, std::initializer_list<const char*> known,
                         const std::string& what,
                         const std::function<void(const std::string&, const std::string&)>& warn) {
  for (const Param& p : params.params()) {
    bool ok = false;
    for (const char* k : known) ok = ok || p.name == k;
    if (!ok) warn(what + ":" + p.name, what + ": parameter \"" + p.name + "\" is ignored");
  }
}

bool non_negative(float v) { return v >= 0.0f && std::isfinite(v); }
bool angular_diameter(float v) { return v >= 0.0f && v <= glm::pi<float>(); }

// RenderMan's lights cast shadows through a shadow map named by
// "shadowname"; Micropoly makes its own maps, so any name turns shadows on
// (the writer writes "raytrace") and its absence, as on the standard
// lights, keeps a file rendering without them.
void read_shadow_name(const ParamList& params, Light& light) {
  light.cast_shadows = !params.get_string("shadowname", "").empty();
}

// The size of a point or spot light (Light::radius) and whether it is a disk
// facing the lit point (soft falloff, the default) or a sphere.
void read_light_radius(const ParamList& params, Light& light) {
  light.radius = params.get_float_checked("micropoly:radius", 0.0f, non_negative, "a finite number >= 0");
  int soft = 1;
  params.get_int("micropoly:softfalloff", 0, 1, &soft);
  light.soft_falloff = soft != 0;
}

}  // namespace

std::vector<float> Parser::material_key(const Material& m) {
  // Equal shading states share one material; the name is not part of it.
  std::vector<float> key{static_cast<float>(m.model),
          m.color.x, m.color.y, m.color.z,
          m.opacity.x, m.opacity.y, m.opacity.z,
          m.ka, m.kd, m.ks, m.roughness,
          m.specular_color.x, m.specular_color.y, m.specular_color.z,
          m.emission.x, m.emission.y, m.emission.z,
          m.metallic, m.specular, static_cast<float>(m.program), m.displacement_bound,
          static_cast<float>(m.program_displaces), static_cast<float>(m.program_shades),
          static_cast<float>(m.displacement_bound_world),
          static_cast<float>(m.program_alpha) + static_cast<float>(m.program_alpha_cut),
          static_cast<float>(m.layered), static_cast<float>(m.retro_diffuse), static_cast<float>(m.multiscatter),
          static_cast<float>(m.program_params.size())};
  key.insert(key.end(), m.program_params.begin(), m.program_params.end());
  return key;
}

int Parser::material_index(const Attributes& attrs) {
  // A material chosen by index (Attribute "micropoly" "integer material").
  if (attrs.material_slot >= 0) return attrs.material_slot;
  Material m = attrs.surface;
  m.color = attrs.color;
  m.opacity = attrs.opacity;
  const std::vector<float> key = material_key(m);
  auto it = material_keys_.find(key);
  if (it != material_keys_.end()) return it->second;
  const int index = static_cast<int>(result_.scene.materials.size());
  result_.scene.materials.push_back(m);
  material_keys_.emplace(key, index);
  return index;
}

void Parser::req_color(ArgReader& args) {
  const std::vector<double> c = args.numbers(3);
  args.done();
  attrs_.color = glm::vec3(c[0], c[1], c[2]);
  attrs_.material_slot = -1;  // the shading state changed
}

void Parser::req_opacity(ArgReader& args) {
  const std::vector<double> o = args.numbers(3);
  args.done();
  attrs_.opacity = glm::vec3(o[0], o[1], o[2]);
  attrs_.material_slot = -1;
}

void Parser::req_surface(ArgReader& args) {
  const std::string name = args.string();
  ParamList params(args, decls_);
  const int line = args.request().line;
  auto warn_param = [&](const std::string& key, const std::string& msg) {
    warn_once("surface-param:" + key, line, msg);
  };
  Material m;
  m.name = name;
  // Emitted radiance added to the shaded color: a Micropoly extension that
  // every supported surface takes.
  auto read_emission = [&] { params.get_floats("emission", &m.emission.x, 3); };
  if (name == "constant") {
    m.model = Material::Model::Constant;
    m.ka = 1.0f;
    m.kd = 0.0f;
    m.ks = 0.0f;
    read_emission();
    warn_unknown_params(params, {"emission"}, "Surface \"constant\"", warn_param);
  } else if (name == "matte" || name == "defaultsurface") {
    m.model = Material::Model::Matte;
    m.ka = params.get_float("Ka", 1.0f);
    m.kd = params.get_float("Kd", 1.0f);
    m.ks = 0.0f;
    read_emission();
    warn_unknown_params(params, {"Ka", "Kd", "emission"}, "Surface \"" + name + "\"", warn_param);
  } else if (name == "micropoly_principled") {
    // Blender's Principled BSDF in the Scene's terms; Color is the base color.
    // Defaults are the Scene's (Material{}).
    m.model = Material::Model::Principled;
    m.metallic = params.get_float("metallic", m.metallic);
    m.roughness = params.get_float("roughness", m.roughness);
    m.specular = params.get_float("specular", m.specular);
    int layered = 0;
    params.get_int("layered", 0, 1, &layered);
    m.layered = layered != 0;
    int retro = 0, multiscatter = 0;
    params.get_int("retrodiffuse", 0, 1, &retro);
    params.get_int("multiscatter", 0, 1, &multiscatter);
    m.retro_diffuse = retro != 0;
    m.multiscatter = multiscatter != 0;
    read_emission();
    warn_unknown_params(params, {"metallic", "roughness", "specular", "layered", "retrodiffuse", "multiscatter", "emission"},
                        "Surface \"micropoly_principled\"", warn_param);
  } else {
    // plastic, and the fallback for any other shader with plastic's defaults.
    m.model = Material::Model::Plastic;
    m.ka = 1.0f;
    m.kd = 0.5f;
    m.ks = 0.5f;
    m.roughness = 0.1f;
    m.specular_color = glm::vec3(1.0f);
    if (name == "plastic") {
      m.ka = params.get_float("Ka", m.ka);
      m.kd = params.get_float("Kd", m.kd);
      m.ks = params.get_float("Ks", m.ks);
      m.roughness = params.get_float("roughness", m.roughness);
      params.get_floats("specularcolor", &m.specular_color.x, 3);
      read_emission();
      warn_unknown_params(params, {"Ka", "Kd", "Ks", "roughness", "specularcolor", "emission"},
                          "Surface \"plastic\"", warn_param);
    } else {
      warn_once("surface:" + name, line,
                "Surface \"" + name + "\" is not supported; using plastic with its defaults");
    }
  }
  attrs_.surface = m;
  attrs_.material_slot = -1;
}

void Parser::req_light_source(ArgReader& args) {
  const int line = args.request().line;
  const std::string shader = args.string();
  // The handle is a number (RIB 3.2) or a string; a string is a handle when
  // an odd number of arguments follows (the handle, then name/value pairs).
  std::string handle;
  if (!args.at_end()) {
    const Arg& next = args.peek();
    if (next.kind == Arg::Kind::Number ||
        (next.kind == Arg::Kind::String && args.remaining() % 2 == 1))
      handle = handle_key(args);
  }
  ParamList params(args, decls_);
  if (shader == "micropoly_environmentlight") {
    // The world's light: not a light of the light list (it lights every
    // primitive, as a World does), so Illuminate does not reach it.
    read_environment_light(args, params);
    return;
  }
  if (static_cast<int>(lights_.size()) >= Limits::kMaxLights)
    args.fail("more than " + std::to_string(Limits::kMaxLights) + " light sources");

  LightRecord rec;
  rec.where = where(line);
  Light& light = rec.light;
  rec.supported = true;
  if (shader == "ambientlight") {
    light.type = Light::Type::Ambient;
  } else if (shader == "distantlight") {
    light.type = Light::Type::Distant;
  } else if (shader == "pointlight") {
    light.type = Light::Type::Point;
  } else if (shader == "spotlight") {
    light.type = Light::Type::Spot;
  } else if (shader == "micropoly_arealight") {
    light.type = Light::Type::Area;
  } else {
    rec.supported = false;
    warn_once("light:" + shader, line,
              "LightSource \"" + shader + "\" is not supported; the light is ignored");
  }
  if (rec.supported) {
    const std::string what = "LightSource \"" + shader + "\"";
    auto warn_param = [&](const std::string& key, const std::string& msg) {
      warn_once("light-param:" + key, line, msg);
    };
    light.intensity = params.get_float("intensity", 1.0f);
    light.color = glm::vec3(1.0f);
    params.get_floats("lightcolor", &light.color.x, 3);
    glm::vec3 from(0.0f), to(0.0f, 0.0f, 1.0f);
    // Ambient light casts no shadows (it has no "shadowname").
    light.cast_shadows = false;
    if (light.type != Light::Type::Ambient) read_shadow_name(params, light);
    switch (light.type) {
      case Light::Type::Ambient:
        warn_unknown_params(params, {"intensity", "lightcolor"}, what, warn_param);
        break;
      case Light::Type::Point:
        params.get_floats("from", &from.x, 3);
        read_light_radius(params, light);
        warn_unknown_params(params,
                            {"intensity", "lightcolor", "from", "shadowname", "micropoly:radius",
                             "micropoly:softfalloff"},
                            what, warn_param);
        break;
      case Light::Type::Distant:
        params.get_floats("from", &from.x, 3);
        params.get_floats("to", &to.x, 3);
        // The sun's angular diameter, in radians.
        light.angle = params.get_float_checked("micropoly:angle", 0.0f, angular_diameter,
                                               "an angle in [0, pi] radians");
        warn_unknown_params(params, {"intensity", "lightcolor", "from", "to", "shadowname", "micropoly:angle"},
                            what, warn_param);
        break;
      case Light::Type::Spot:
        params.get_floats("from", &from.x, 3);
        params.get_floats("to", &to.x, 3);
        // spotlight's defaults: coneangle 30 degrees, conedeltaangle 5 degrees
        // (both in radians), beamdistribution 2.
        light.cone_angle = params.get_float("coneangle", glm::radians(30.0f));
        light.cone_delta_angle = params.get_float("conedeltaangle", glm::radians(5.0f));
        light.beam_distribution = params.get_float("beamdistribution", 2.0f);
        read_light_radius(params, light);
        warn_unknown_params(params,
                            {"intensity", "lightcolor", "from", "to", "coneangle", "conedeltaangle",
                             "beamdistribution", "shadowname", "micropoly:radius", "micropoly:softfalloff"},
                            what, warn_param);
        break;
      case Light::Type::Area: {
        // A rectangle or ellipse centred on "from", emitting towards "to";
        // "width" along "axis", "height" across it.
        params.get_floats("from", &from.x, 3);
        params.get_floats("to", &to.x, 3);
        const std::string shape = params.get_string("shape", "rectangle");
        if (shape == "ellipse")
          light.shape = Light::Shape::Ellipse;
        else if (shape == "rectangle")
          light.shape = Light::Shape::Rectangle;
        else
          args.fail("\"shape\" must be \"rectangle\" or \"ellipse\", not \"" + shape + "\"");
        glm::vec3 axis(1.0f, 0.0f, 0.0f);
        params.get_floats("axis", &axis.x, 3);
        light.axis_u = glm::vec3(attrs_.ctm * glm::vec4(axis, 0.0f));
        light.size_u = params.get_float("width", 1.0f);
        light.size_v = params.get_float("height", 1.0f);
        if (!(light.size_u >= 0.0f && light.size_v >= 0.0f)) args.fail("negative area light size");
        warn_unknown_params(params,
                            {"intensity", "lightcolor", "from", "to", "shape", "axis", "width", "height",
                             "shadowname"},
                            what, warn_param);
        break;
      }
    }
    if ((light.type == Light::Type::Distant || light.type == Light::Type::Spot ||
         light.type == Light::Type::Area) && from == to)
      args.fail("\"from\" and \"to\" coincide: the light has no direction");
    // Light positions are given in the current coordinate system (the
    // shader space at declaration): camera space before WorldBegin.
    light.position = glm::vec3(attrs_.ctm * glm::vec4(from, 1.0f));
    // The direction is transformed as a vector (the same as the difference of
    // the transformed points for the affine transformations lights live in),
    // so "from" [0 0 0] "to" d under a Translate gives back d exactly.
    rec.direction = glm::vec3(attrs_.ctm * glm::vec4(to - from, 0.0f));
    rec.in_camera = !in_world_;
  }
  const int index = static_cast<int>(lights_.size());
  // Primitives placed before the light are not lit by it in RenderMan.
  rec.off_some = prims_emitted_ > 0;
  lights_.push_back(rec);
  if (!handle.empty()) light_handles_[handle] = index;
  // Declaring a light turns it on in the current light list (an attribute).
  attrs_.lights_on.resize(static_cast<size_t>(index) + 1, 0);
  attrs_.lights_on[static_cast<size_t>(index)] = 1;
  if (rec.supported && in_world_) finish_light(lights_.back(), line);
}

void Parser::finish_light(LightRecord& rec, int line) {
  Light& light = rec.light;
  if (rec.in_camera) {
    const glm::mat4& to_world = camera_inverse(line);
    light.position = glm::vec3(to_world * glm::vec4(light.position, 1.0f));
    rec.direction = glm::vec3(to_world * glm::vec4(rec.direction, 0.0f));
    if (light.type == Light::Type::Area) light.axis_u = glm::vec3(to_world * glm::vec4(light.axis_u, 0.0f));
    rec.in_camera = false;
  }
  if (light.type == Light::Type::Distant || light.type == Light::Type::Spot ||
      light.type == Light::Type::Area) {
    const glm::vec3 d = rec.direction;
    const float len = glm::length(d);
    if (!(len > 0.0f) || !std::isfinite(len))
      throw RibError(rec.where + ": LightSource: the light direction is degenerate after transformation");
    // Normalised; a direction already of unit length to float precision is
    // kept bit for bit (normalising again would only add rounding), so that
    // written scenes read back exactly.
    light.direction = std::fabs(len - 1.0f) <= 4.0f * FLT_EPSILON ? d : d / len;
  }
}

void Parser::convert_camera_lights(int line) {
  for (LightRecord& rec : lights_)
    if (rec.supported && rec.in_camera) finish_light(rec, line);
}

void Parser::req_illuminate(ArgReader& args) {
  const std::string handle = handle_key(args);
  const int on = args.integer(-2147483647LL - 1, 2147483647LL);
  args.done();
  auto it = light_handles_.find(handle);
  if (it == light_handles_.end()) args.fail("unknown light handle " + handle);
  const size_t index = static_cast<size_t>(it->second);
  if (attrs_.lights_on.size() <= index) attrs_.lights_on.resize(index + 1, 0);
  attrs_.lights_on[index] = on != 0;
}

}  // namespace mp::rib
