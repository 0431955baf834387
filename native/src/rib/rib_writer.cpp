// Scene -> RIB. Every value is written so that the reader (rib_reader.h)
// reproduces it bit for bit: floats in a form that reads back to the same
// float, transformations as whole matrices (no decomposition), face loops in
// their original order (the reader keeps the order unless the orientation is
// flipped, which the writer never does), and materials as an indexed table
// (Attribute "micropoly" "integer material") so that indices, duplicates and
// unused entries survive. The standard shading requests are written too, so
// other RenderMan renderers see the same surfaces.
#include "rib/rib_writer.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>

#include "io/texture_io.h"
#include "micropoly/error.h"
#include "rib/rib_lexer.h"

namespace mp {
namespace {

// --- values -------------------------------------------------------------------

void put_float(std::string& out, float v) {
  // The shortest decimal that names v, unless reading it as the reader does
  // (to double, then rounded to float) would land on a neighbour; 9
  // significant digits always read back exactly (they lie far from the
  // midpoints between floats, so the double step cannot tip them over).
  char buf[48];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  double back = 0.0;
  std::from_chars(buf, r.ptr, back);
  if (static_cast<float>(back) != v) r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 9);
  out.append(buf, r.ptr);
}

void put_int(std::string& out, long long v) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void put_octal(std::string& out, unsigned char c) {
  // Always three digits, so a digit that follows is not read as part of it.
  out += '\\';
  out += static_cast<char>('0' + ((c >> 6) & 7));
  out += static_cast<char>('0' + ((c >> 3) & 7));
  out += static_cast<char>('0' + (c & 7));
}

// A quoted RIB string. Valid UTF-8 is kept as is; quotes, backslashes and
// control characters are escaped, and bytes that are not valid UTF-8 are
// written as octal escapes (which the reader takes as raw bytes). NUL has no
// escape in RIB (\000 is invalid) and is dropped.
void put_string(std::string& out, std::string_view s) {
  out += '"';
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {
      const size_t n = rib::utf8_sequence_length(s, i);
      if (n == 0) {
        put_octal(out, c);
        ++i;
      } else {
        out.append(s.substr(i, n));
        i += n;
      }
      continue;
    }
    ++i;
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case 0: break;
      default:
        if (c < 0x20 || c == 0x7F)
          put_octal(out, c);
        else
          out += static_cast<char>(c);
    }
  }
  out += '"';
}

void put_floats(std::string& out, const float* v, size_t n) {
  out += '[';
  for (size_t i = 0; i < n; ++i) {
    if (i) out += ' ';
    put_float(out, v[i]);
  }
  out += ']';
}

void put_vec3(std::string& out, const glm::vec3& v) { put_floats(out, &v.x, 3); }

void put_points(std::string& out, const std::vector<glm::vec3>& pts) {
  // Long arrays are broken into lines of a few points to stay readable.
  out += '[';
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i) out += (i % 4 == 0) ? "\n    " : "  ";
    for (int k = 0; k < 3; ++k) {
      if (k) out += ' ';
      put_float(out, pts[i][k]);
    }
  }
  out += ']';
}

void put_ints(std::string& out, const std::vector<int>& v) {
  out += '[';
  for (size_t i = 0; i < v.size(); ++i) {
    if (i) out += (i % 32 == 0) ? "\n    " : " ";
    put_int(out, v[i]);
  }
  out += ']';
}

// A matrix as RIB's 16 numbers. GLM stores columns; RenderMan writes rows of
// its row-vector matrix, which is the transpose: the same 16 floats in order.
void put_matrix(std::string& out, const glm::mat4& m) {
  out += '[';
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      if (c || r) out += ' ';
      put_float(out, m[c][r]);
    }
  out += ']';
}

// "name" [value] pairs.
void param(std::string& out, const char* name, float v) {
  out += " \"";
  out += name;
  out += "\" ";
  put_floats(out, &v, 1);
}
void param(std::string& out, const char* name, const glm::vec3& v) {
  out += " \"";
  out += name;
  out += "\" ";
  put_vec3(out, v);
}
// A list of any length, declared inline as float[n] (none when empty).
void param_list(std::string& out, const char* name, const std::vector<float>& v) {
  if (v.empty()) return;
  out += " \"float[" + std::to_string(v.size()) + "] ";
  out += name;
  out += "\" ";
  put_floats(out, v.data(), v.size());
}
void param(std::string& out, const char* name, long long v) {
  out += " \"";
  out += name;
  out += "\" [";
  put_int(out, v);
  out += ']';
}
void param(std::string& out, const char* name, std::string_view v) {
  out += " \"";
  out += name;
  out += "\" [";
  put_string(out, v);
  out += ']';
}

// True when `v` is not `def` bit for bit (-0 differs from 0): extensions
// are written only when they differ from the reader's default, so that
// plain scenes stay standard RIB, and a value that differs in any bit is
// written so that it comes back exactly.
bool differs(float v, float def) { return v != def || std::signbit(v) != std::signbit(def); }

// --- scene parts --------------------------------------------------------------------

const char* filter_name(PixelFilter f) {
  switch (f) {
    case PixelFilter::Box: return "box";
    case PixelFilter::Gaussian: return "gaussian";
    case PixelFilter::Triangle: return "triangle";
    case PixelFilter::BlackmanHarris: return "blackman-harris";
  }
  return "gaussian";
}

// MotionBegin with the Scene's motion steps as times over the shutter [0, 1].
void begin_motion(std::string& o, size_t steps, const char* indent) {
  o += indent;
  o += "MotionBegin [";
  for (size_t k = 0; k < steps; ++k) {
    if (k) o += ' ';
    put_float(o, float(double(k) / double(steps - 1)));
  }
  o += "]\n";
}

// A transformation, or one per motion step in a motion block.
void write_transform(std::string& o, const glm::mat4& m, const std::vector<glm::mat4>& steps, const char* indent) {
  if (steps.empty()) {
    o += indent;
    o += "Transform ";
    put_matrix(o, m);
    o += '\n';
    return;
  }
  begin_motion(o, steps.size(), indent);
  for (const glm::mat4& s : steps) {
    o += indent;
    o += "  Transform ";
    put_matrix(o, s);
    o += '\n';
  }
  o += indent;
  o += "MotionEnd\n";
}

const std::vector<glm::mat4>& motion_transforms(const Mesh& m) { return m.motion_object_to_world; }
const std::vector<glm::mat4>& motion_transforms(const BezierPatches&) {
  static const std::vector<glm::mat4> none;
  return none;
}

void write_options(std::string& o, const RenderSettings& s, const Camera& c) {
  // Settings with no RenderMan request (docs/rib.md, "Option micropoly").
  o += "Option \"micropoly\"";
  param(o, "string boundsplit", s.bound_split == BoundSplitMethod::Breadth ? "breadth" : "bounded");
  param(o, "float boundsplitmemory", s.bound_split_memory_mib);
  param(o, "integer maxgridsize", static_cast<long long>(s.max_grid_size));
  param(o, "integer maxsplitdepth", static_cast<long long>(s.max_split_depth));
  param(o, "integer backfaceculling", static_cast<long long>(s.backface_culling ? 1 : 0));
  param(o, "integer depthandnormal", static_cast<long long>(s.depth_and_normal_passes ? 1 : 0));
  // Shadow settings, only when they differ from the defaults (the reader's
  // and the Scene's are the same).
  const RenderSettings def;
  if (s.shadows != def.shadows) param(o, "integer shadows", static_cast<long long>(s.shadows ? 1 : 0));
  if (differs(s.shadow_memory_mib, def.shadow_memory_mib)) param(o, "float shadowmemory", s.shadow_memory_mib);
  if (differs(s.shadow_shading_rate, def.shadow_shading_rate))
    param(o, "float shadowshadingrate", s.shadow_shading_rate);
  if (s.occlusion_culling != def.occlusion_culling)
    param(o, "integer occlusionculling", static_cast<long long>(s.occlusion_culling ? 1 : 0));
  if (s.sample_culling != def.sample_culling)
    param(o, "integer sampleculling", static_cast<long long>(s.sample_culling ? 1 : 0));
  if (s.holdout_covers != def.holdout_covers)
    param(o, "integer holdoutcovers", static_cast<long long>(s.holdout_covers ? 1 : 0));
  if (s.world_probes != def.world_probes)
    param(o, "integer worldshadowdirections", static_cast<long long>(s.world_probes));
  if (differs(s.dof_dice_factor, def.dof_dice_factor)) param(o, "float focusfactor", s.dof_dice_factor);
  if (differs(s.texture_filter_width, def.texture_filter_width))
    param(o, "float texturefilterwidth", s.texture_filter_width);
  if (s.sampler != def.sampler)
    param(o, "string sampler", s.sampler == Sampler::Tiles  ? "tiles"
                               : s.sampler == Sampler::Bins ? "bins"
                                                            : "micropolygons");
  if (s.bound_split_chain != def.bound_split_chain)
    param(o, "integer boundsplitchain", static_cast<long long>(s.bound_split_chain));
  if (s.bound_split_steps != def.bound_split_steps)
    param(o, "integer boundsplitsteps", static_cast<long long>(s.bound_split_steps));
  if (s.resolver != def.resolver) param(o, "string resolver", s.resolver == Resolver::Tiles ? "tiles" : "pixels");
  if (s.occlusion_waves != def.occlusion_waves)
    param(o, "string occlusionwaves", s.occlusion_waves == OcclusionWaves::On ? "on" : "off");
  if (differs(s.sample_memory_mib, def.sample_memory_mib)) param(o, "float samplememory", s.sample_memory_mib);
  if (s.visibility_first != def.visibility_first)
    param(o, "string visibilityfirst", s.visibility_first == VisibilityFirst::On ? "on" : "off");
  if (c.lens_radius > 0.0f) {
    param(o, "integer apertureblades", static_cast<long long>(c.aperture_blades));
    param(o, "float aperturerotation", c.aperture_rotation);
    param(o, "float apertureratio", c.aperture_ratio);
  }
  o += '\n';
}

void write_image_and_camera(std::string& o, const Scene& scene) {
  const RenderSettings& s = scene.settings;
  const Camera& c = scene.camera;
  o += "Format ";
  put_int(o, s.width);
  o += ' ';
  put_int(o, s.height);
  o += ' ';
  put_float(o, s.pixel_aspect);
  o += "\nCropWindow ";
  const float crop[4] = {s.crop_x0, s.crop_x1, s.crop_y0, s.crop_y1};
  put_floats(o, crop, 4);
  o += "\nPixelSamples ";
  put_int(o, s.samples_x);
  o += ' ';
  put_int(o, s.samples_y);
  o += "\nPixelFilter ";
  put_string(o, filter_name(s.filter));
  o += ' ';
  put_float(o, s.filter_width);
  o += ' ';
  put_float(o, s.filter_width);
  o += "\nShadingRate ";
  put_float(o, s.shading_rate);
  // RenderMan needs a positive near plane; a Scene may use 0, for which the
  // smallest positive float behaves the same (nothing lies closer).
  o += "\nClipping ";
  put_float(o, c.clip_near > 0.0f ? c.clip_near : std::numeric_limits<float>::denorm_min());
  o += ' ';
  put_float(o, c.clip_far);
  o += '\n';
  if (c.projection == Camera::Projection::Perspective) {
    o += "Projection \"perspective\"";
    param(o, "fov", c.fov_degrees);
    o += '\n';
    // Radius = focallength / (2 fstop): written with fstop 0.5, so the
    // focal length is the radius itself (exact, and finite for any radius).
    if (c.lens_radius > 0.0f) {
      o += "DepthOfField 0.5 ";
      put_float(o, c.lens_radius);
      o += ' ';
      put_float(o, c.focus_distance);
      o += '\n';
    }
  } else {
    o += "Projection \"orthographic\"\n";
  }
  // left == right (or bottom == top) means "derived from the aspect ratio":
  // the reader's default when no ScreenWindow is given.
  if (c.screen_left != c.screen_right || c.screen_bottom != c.screen_top) {
    o += "ScreenWindow ";
    const float w[4] = {c.screen_left, c.screen_right, c.screen_bottom, c.screen_top};
    put_floats(o, w, 4);
    o += '\n';
  }
  // The reader takes the transformation at WorldBegin as RenderMan's
  // left-handed world-to-camera and mirrors z into the Scene's right-handed
  // camera space; mirroring here first gives back the same matrix (negating
  // a row is exact).
  auto mirrored = [](glm::mat4 m) {
    for (int col = 0; col < 4; ++col) m[col][2] = m[col][2] == 0.0f ? 0.0f : -m[col][2];  // no "-0"
    return m;
  };
  if (scene.motion_steps >= 2) o += "Shutter 0 1\n";
  if (!scene.shutter_curve.empty()) {
    o += "Option \"micropoly\" \"float[" + std::to_string(scene.shutter_curve.size()) + "] shuttercurve\" ";
    put_floats(o, scene.shutter_curve.data(), scene.shutter_curve.size());
    o += '\n';
  }
  std::vector<glm::mat4> steps;
  for (const glm::mat4& m : c.motion_world_to_camera) steps.push_back(mirrored(m));
  o += "# world to camera, z mirrored into RenderMan's left-handed camera space\n";
  write_transform(o, mirrored(c.world_to_camera), steps, "");
}

// Shadows as RenderMan's lights ask for them, by naming a shadow map: any
// name will do for the reader, and "raytrace" is what other renderers take
// as "trace shadow rays". The light's size for soft shadows is an extension,
// written when it is not the default. Ambient lights cast no shadows and
// have no size.
void write_light_shadows(std::string& o, const Light& l) {
  if (l.type == Light::Type::Ambient) return;
  if (l.cast_shadows) param(o, "string shadowname", "raytrace");
  if (l.type == Light::Type::Point || l.type == Light::Type::Spot) {
    if (differs(l.radius, 0.0f)) param(o, "float micropoly:radius", l.radius);
    if (!l.soft_falloff) param(o, "integer micropoly:softfalloff", static_cast<long long>(0));
  } else if (l.type == Light::Type::Distant && differs(l.angle, 0.0f)) {
    param(o, "float micropoly:angle", l.angle);
  }
}

void write_light(std::string& o, const Light& l, int handle) {
  // Lights with a direction are declared at the origin of a translated frame
  // with "to" = the direction: the reader takes the direction as the
  // transformed "to" - "from" = the written vector, exactly (and keeps a
  // unit-length one as is), and the position as the translation, exactly.
  const bool directed = l.type == Light::Type::Distant || l.type == Light::Type::Spot ||
                        l.type == Light::Type::Area;
  if (directed) {
    o += "TransformBegin\n  Translate";
    for (int k = 0; k < 3; ++k) {
      o += ' ';
      put_float(o, l.position[k]);
    }
    o += "\n  ";
  }
  o += "LightSource ";
  switch (l.type) {
    case Light::Type::Ambient: o += "\"ambientlight\" "; break;
    case Light::Type::Distant: o += "\"distantlight\" "; break;
    case Light::Type::Point: o += "\"pointlight\" "; break;
    case Light::Type::Spot: o += "\"spotlight\" "; break;
    case Light::Type::Area: o += "\"micropoly_arealight\" "; break;
  }
  put_int(o, handle);
  param(o, "intensity", l.intensity);
  param(o, "lightcolor", l.color);
  if (l.type == Light::Type::Point) param(o, "from", l.position);
  if (directed) {
    // A zero direction (the renderer falls back to -z) is not valid RIB.
    const glm::vec3 d = glm::length(l.direction) > 0.0f ? l.direction : glm::vec3(0.0f, 0.0f, -1.0f);
    param(o, "from", glm::vec3(0.0f));
    param(o, "to", d);
  }
  if (l.type == Light::Type::Spot) {
    param(o, "coneangle", l.cone_angle);
    param(o, "conedeltaangle", l.cone_delta_angle);
    param(o, "beamdistribution", l.beam_distribution);
  } else if (l.type == Light::Type::Area) {
    param(o, "string shape", l.shape == Light::Shape::Ellipse ? "ellipse" : "rectangle");
    param(o, "vector axis", l.axis_u);
    param(o, "float width", l.size_u);
    param(o, "float height", l.size_v);
  }
  write_light_shadows(o, l);
  o += directed ? "\nTransformEnd\n" : "\n";
}

// The standard shading requests for a material, then the micropoly
// attribute that makes that state Scene material `index` (with its name).
void write_material(std::string& o, const Material& m, int index, const char* indent,
                    const std::vector<MaterialProgram>& programs) {
  o += indent;
  o += "Color ";
  put_vec3(o, m.color);
  o += '\n';
  o += indent;
  o += "Opacity ";
  put_vec3(o, m.opacity);
  o += '\n';
  o += indent;
  o += "Surface ";
  switch (m.model) {
    case Material::Model::Constant: o += "\"constant\""; break;
    case Material::Model::Matte:
      o += "\"matte\"";
      param(o, "Ka", m.ka);
      param(o, "Kd", m.kd);
      break;
    case Material::Model::Plastic:
      o += "\"plastic\"";
      param(o, "Ka", m.ka);
      param(o, "Kd", m.kd);
      param(o, "Ks", m.ks);
      param(o, "roughness", m.roughness);
      param(o, "specularcolor", m.specular_color);
      break;
    case Material::Model::Principled:
      o += "\"micropoly_principled\"";
      param(o, "float metallic", m.metallic);
      param(o, "roughness", m.roughness);
      param(o, "float specular", m.specular);
      if (m.layered) param(o, "integer layered", static_cast<long long>(1));
      if (m.retro_diffuse) param(o, "integer retrodiffuse", static_cast<long long>(1));
      if (m.multiscatter) param(o, "integer multiscatter", static_cast<long long>(1));
      break;
  }
  // Emission is a Micropoly extension on every surface; omitted when black
  // so plain materials stay standard RIB.
  if (m.emission != glm::vec3(0.0f)) param(o, "color emission", m.emission);
  o += '\n';
  o += indent;
  o += "Attribute \"micropoly\"";
  param(o, "integer material", static_cast<long long>(index));
  param(o, "string materialname", m.name);
  if (m.program >= 0 && static_cast<size_t>(m.program) < programs.size()) {
    param(o, "string program", programs[static_cast<size_t>(m.program)].source);
    param_list(o, "programparams", m.program_params);
    param(o, "integer programdisplaces", static_cast<long long>(m.program_displaces ? 1 : 0));
    param(o, "integer programshades", static_cast<long long>(m.program_shades ? 1 : 0));
    if (m.program_alpha) param(o, "integer programalpha", static_cast<long long>(m.program_alpha_cut ? 2 : 1));
    param(o, "float displacementbound", m.displacement_bound);
    if (m.displacement_bound_world) param(o, "integer displacementworld", static_cast<long long>(1));
  }
  o += '\n';
}

// Ray visibility as RenderMan's attribute ("transmission" rays are its
// shadow rays), only for an object that is hidden from one of them.
void write_visibility(std::string& o, bool visible_camera, bool cast_shadows) {
  if (visible_camera && cast_shadows) return;
  o += "  Attribute \"visibility\"";
  param(o, "int camera", static_cast<long long>(visible_camera ? 1 : 0));
  param(o, "int transmission", static_cast<long long>(cast_shadows ? 1 : 0));
  o += '\n';
}

// Name, placement, sides, visibility and material: what a mesh and a patch
// set share.
void write_object_info(std::string& o, const ObjectInfo& info) {
  if (info == ObjectInfo{}) return;
  o += "  Attribute \"micropoly\"";
  param(o, "color objectcolor", glm::vec3(info.color));
  param(o, "float objectalpha", info.color.w);
  param(o, "float objectindex", info.pass_index);
  param(o, "float objectrandom", info.random);
  std::vector<float> attributes;
  for (const glm::vec4& a : info.attributes) attributes.insert(attributes.end(), {a.x, a.y, a.z, a.w});
  param_list(o, "objectattributes", attributes);
  o += '\n';
}

template <typename Object>
void write_object_state(std::string& o, const Object& object, const std::vector<Material>& materials,
                        const std::vector<MaterialProgram>& programs) {
  o += "  Attribute \"identifier\"";
  param(o, "name", object.name);
  o += '\n';
  write_transform(o, object.object_to_world, motion_transforms(object), "  ");
  o += object.double_sided ? "  Sides 2\n" : "  Sides 1\n";
  write_visibility(o, object.visible_camera, object.cast_shadows);
  write_object_info(o, object.info);
  const int material = object.material;
  write_material(o, materials[static_cast<size_t>(material)], material, "  ", programs);
}

// The mesh's geometry request with the given points.
void write_mesh_geometry(std::string& o, const Mesh& m, const std::vector<glm::vec3>& points) {
  if (m.scheme == SubdivScheme::CatmullClark) {
    o += "  SubdivisionMesh \"catmull-clark\" ";
    put_ints(o, m.face_vertex_counts);
    o += ' ';
    put_ints(o, m.face_vertex_indices);
    // Tags: interpolateboundary always (RenderMan's default differs from the
    // Scene's), one crease per edge (keeps each edge's sharpness), then all
    // corners and all holes in one tag each.
    std::vector<std::string> tags = {"interpolateboundary"};
    std::vector<int> nargs, ints;
    std::vector<float> floats;
    const int mode = m.boundary == BoundaryInterpolation::None       ? 0
                     : m.boundary == BoundaryInterpolation::EdgeOnly ? 2
                                                                     : 1;
    nargs.insert(nargs.end(), {1, 0});
    ints.push_back(mode);
    for (size_t e = 0; e < m.crease_sharpness.size(); ++e) {
      tags.push_back("crease");
      nargs.insert(nargs.end(), {2, 1});
      ints.insert(ints.end(), {m.crease_vertices[2 * e], m.crease_vertices[2 * e + 1]});
      floats.push_back(m.crease_sharpness[e]);
    }
    if (!m.corner_vertices.empty()) {
      tags.push_back("corner");
      nargs.insert(nargs.end(), {static_cast<int>(m.corner_vertices.size()), static_cast<int>(m.corner_sharpness.size())});
      ints.insert(ints.end(), m.corner_vertices.begin(), m.corner_vertices.end());
      floats.insert(floats.end(), m.corner_sharpness.begin(), m.corner_sharpness.end());
    }
    if (!m.hole_faces.empty()) {
      tags.push_back("hole");
      nargs.insert(nargs.end(), {static_cast<int>(m.hole_faces.size()), 0});
      ints.insert(ints.end(), m.hole_faces.begin(), m.hole_faces.end());
    }
    o += "\n    [";
    for (size_t t = 0; t < tags.size(); ++t) {
      if (t) o += ' ';
      put_string(o, tags[t]);
    }
    o += "] ";
    put_ints(o, nargs);
    o += ' ';
    put_ints(o, ints);
    o += ' ';
    put_floats(o, floats.data(), floats.size());
  } else {
    // Catmull-Clark tags have no effect on polygon meshes and are not written.
    o += "  PointsPolygons ";
    put_ints(o, m.face_vertex_counts);
    o += ' ';
    put_ints(o, m.face_vertex_indices);
  }
  o += "\n    \"P\" ";
  put_points(o, points);
  if (!m.face_materials.empty()) {
    o += "\n    \"uniform integer micropoly:material\" ";
    put_ints(o, m.face_materials);
  }
  // Smooth shading normals (RenderMan's "N"; polygon meshes only).
  if (!m.corner_normals.empty() && m.scheme == SubdivScheme::None) {
    o += "\n    \"facevarying normal N\" ";
    put_points(o, m.corner_normals);
  }
  // UV layers and the Generated texture space, for material programs.
  for (size_t k = 0; k < m.uv_layers.size(); ++k) {
    o += "\n    \"facevarying float[2] micropoly:uv" + std::to_string(k) + "\" ";
    put_floats(o, &m.uv_layers[k].data()->x, 2 * m.uv_layers[k].size());
  }
  if (m.texspace_location != glm::vec3(0.0f) || m.texspace_size != glm::vec3(0.0f)) {
    o += "\n    \"constant float[3] micropoly:texspacelocation\" ";
    put_vec3(o, m.texspace_location);
    o += " \"constant float[3] micropoly:texspacesize\" ";
    put_vec3(o, m.texspace_size);
  }
  o += '\n';
}

void write_mesh(std::string& o, const Mesh& m, const std::vector<Material>& materials,
                const std::vector<MaterialProgram>& programs) {
  o += "AttributeBegin\n";
  write_object_state(o, m, materials, programs);
  if (m.motion_points.empty()) {
    write_mesh_geometry(o, m, m.points);
  } else {
    // A deforming mesh: the whole request once per motion step.
    begin_motion(o, m.motion_points.size(), "  ");
    for (const std::vector<glm::vec3>& step : m.motion_points) write_mesh_geometry(o, m, step);
    o += "  MotionEnd\n";
  }
  o += "AttributeEnd\n";
}

// One Patch request per 4x4 net in the default Bezier basis (step 3), with
// its corner UVs (u fastest, RenderMan's order for a patch's varying values).
void write_patch_requests(std::string& o, const BezierPatches& b) {
  const std::vector<glm::vec3>& control_points = b.control_points;
  o += "  Basis \"bezier\" 3 \"bezier\" 3\n";
  for (size_t p = 0; p + 16 <= control_points.size(); p += 16) {
    o += "  Patch \"bicubic\" \"P\" ";
    put_points(o, std::vector<glm::vec3>(control_points.begin() + static_cast<long>(p),
                                         control_points.begin() + static_cast<long>(p + 16)));
    for (size_t k = 0; k < b.uv_layers.size(); ++k) {
      const glm::vec2* c = &b.uv_layers[k][p / 4];
      const glm::vec2 corners[4] = {c[0], c[1], c[3], c[2]};
      o += " \"varying float[2] micropoly:uv" + std::to_string(k) + "\" ";
      put_floats(o, &corners[0].x, 8);
    }
    o += '\n';
  }
}

// Hair tubes keep their round dicing (BezierPatches::round_u), ribbons
// their kind (BezierPatches::ribbons).
void write_round_u(std::string& o, const BezierPatches& b) {
  if (b.round_u) o += "  Attribute \"micropoly\" \"int roundu\" [1]\n";
  if (b.ribbons) o += "  Attribute \"micropoly\" \"int ribbons\" [1]\n";
}

void write_patches(std::string& o, const BezierPatches& b, const std::vector<Material>& materials,
                   const std::vector<MaterialProgram>& programs) {
  // The reader joins consecutive patches of one attribute block into one set.
  o += "AttributeBegin\n";
  write_object_state(o, b, materials, programs);
  write_round_u(o, b);
  write_patch_requests(o, b);
  o += "AttributeEnd\n";
}

// A prototype as RenderMan retained geometry (ObjectBegin/ObjectEnd), or
// nothing where RIB cannot say it: a definition holds geometry only, and its
// instances bring the material, sidedness and visibility, so its surfaces
// must agree on those (meshes say their own material per face).
struct WrittenPrototype {
  bool as_object = false;
  int material = 0;  // what its instances take unless they choose one
  bool double_sided = true, visible_camera = true, cast_shadows = true;
};

WrittenPrototype prototype_state(const Prototype& p) {
  WrittenPrototype w;
  bool first = true, agree = true;
  auto take = [&](const auto& s) {
    if (first) {
      w.double_sided = s.double_sided, w.visible_camera = s.visible_camera, w.cast_shadows = s.cast_shadows;
      first = false;
    }
    agree = agree && s.double_sided == w.double_sided && s.visible_camera == w.visible_camera &&
            s.cast_shadows == w.cast_shadows;
  };
  for (const Mesh& m : p.meshes) take(m);
  for (const BezierPatches& b : p.bezier_patches) {
    take(b);
    agree = agree && b.material == p.bezier_patches.front().material;
  }
  w.material = !p.bezier_patches.empty() ? p.bezier_patches.front().material
               : !p.meshes.empty()       ? p.meshes.front().material
                                         : 0;
  w.as_object = agree && !first;
  return w;
}

// ObjectBegin <handle> ... ObjectEnd: each surface in its own transform,
// meshes' materials per face (their own `material` spelt out where it is
// not the one instances take).
void write_prototype(std::string& o, const Prototype& p, const WrittenPrototype& w, int handle) {
  o += "ObjectBegin ";
  put_int(o, handle);
  o += '\n';
  for (const Mesh& m : p.meshes) {
    o += "AttributeBegin\n  ConcatTransform ";
    put_matrix(o, m.object_to_world);
    o += '\n';
    if (m.face_materials.empty() && m.material != w.material) {
      Mesh spelt = m;
      spelt.face_materials.assign(m.face_vertex_counts.size(), m.material);
      write_mesh_geometry(o, spelt, spelt.points);
    } else {
      write_mesh_geometry(o, m, m.points);
    }
    o += "AttributeEnd\n";
  }
  for (const BezierPatches& b : p.bezier_patches) {
    o += "AttributeBegin\n  ConcatTransform ";
    put_matrix(o, b.object_to_world);
    o += '\n';
    write_round_u(o, b);
    write_patch_requests(o, b);
    o += "AttributeEnd\n";
  }
  o += "ObjectEnd\n";
}

// One ObjectInstance with the instance's transform (over the shutter when it
// moves) and the attributes it brings.
void write_instance(std::string& o, const Instance& inst, const WrittenPrototype& w, int handle,
                    const std::vector<Material>& materials, const std::vector<MaterialProgram>& programs) {
  o += "AttributeBegin\n";
  write_transform(o, inst.object_to_world, inst.motion_object_to_world, "  ");
  const bool double_sided = inst.double_sided >= 0 ? inst.double_sided == 1 : w.double_sided;
  o += double_sided ? "  Sides 2\n" : "  Sides 1\n";
  if (inst.reverse_orientation) o += "  ReverseOrientation\n";
  write_visibility(o, inst.visible_camera && w.visible_camera, inst.cast_shadows && w.cast_shadows);
  write_object_info(o, inst.info);
  const int material = inst.material >= 0 ? inst.material : w.material;
  write_material(o, materials[static_cast<size_t>(material)], material, "  ", programs);
  o += "  ObjectInstance ";
  put_int(o, handle);
  o += "\nAttributeEnd\n";
}

void flush(std::ostream& out, std::string& text) {
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  text.clear();
  if (!out) throw Error("writing RIB failed (stream error)");
}

// Texture images go to files in `folder` ("<k>.exr"), named in the RIB as
// `reference`/<k>.exr; one Option "micropoly" per image keeps their order.
void write_images(std::string& o, const std::vector<Image>& images, const std::string& folder,
                  const std::string& reference) {
  if (images.empty()) return;
  if (folder.empty()) throw Error("the scene has texture images; they need a folder to be written to");
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw Error("cannot create texture folder '" + folder + "': " + ec.message());
  for (size_t k = 0; k < images.size(); ++k) {
    const std::string file = std::to_string(k) + ".exr";
    write_texture_image((std::filesystem::path(folder) / file).string(), images[k]);
    o += "Option \"micropoly\" \"string image\" ";
    put_string(o, images[k].name);
    o += " \"string imagefile\" ";
    put_string(o, (std::filesystem::path(reference) / file).generic_string());
    o += " \"integer imagesrgb\" ";
    put_int(o, images[k].srgb ? 1 : 0);
    o += '\n';
  }
}

// The World as LightSource "micropoly_environmentlight" (docs/rib.md): its
// program, or its map written beside the RIB as a texture.
void write_world(std::string& o, const Scene& scene, const std::string& folder, const std::string& reference) {
  const World& w = scene.world;
  if (!w.present()) return;
  o += "LightSource \"micropoly_environmentlight\" \"world\"";
  if (w.program >= 0) {
    const MaterialProgram& p = scene.material_programs[size_t(w.program)];
    param(o, "string programname", p.name);
    param(o, "string program", p.source);
    param_list(o, "programparams", w.program_params);
    param(o, "integer bakewidth", static_cast<long long>(w.bake_width));
  } else {
    if (folder.empty()) throw Error("the scene's world map needs a folder to be written to");
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) throw Error("cannot create texture folder '" + folder + "': " + ec.message());
    Image map;
    map.name = "world";
    map.width = w.width, map.height = w.height;
    map.pixels.resize(size_t(w.width) * size_t(w.height));
    for (size_t i = 0; i < map.pixels.size(); ++i)
      map.pixels[i] = glm::vec4(w.radiance[4 * i], w.radiance[4 * i + 1], w.radiance[4 * i + 2], w.radiance[4 * i + 3]);
    write_texture_image((std::filesystem::path(folder) / "world.exr").string(), map);
    param(o, "string mapname", (std::filesystem::path(reference) / "world.exr").generic_string());
  }
  param(o, "integer camera", static_cast<long long>(w.camera ? 1 : 0));
  param(o, "float diffuse", w.diffuse);
  param(o, "float glossy", w.glossy);
  if (w.cast_shadows) param(o, "string shadowname", "raytrace");
  o += '\n';
}

// The scene's meshes and patch sets, each flushed to `out` once written.
void write_surfaces(std::string& o, std::ostream& out, const Scene& scene, const std::vector<Material>& materials,
                    const std::vector<MaterialProgram>& programs) {
  for (const Mesh& m : scene.meshes) {
    write_mesh(o, m, materials, programs);
    flush(out, o);
  }
  for (const BezierPatches& b : scene.bezier_patches) {
    write_patches(o, b, materials, programs);
    flush(out, o);
  }
}

// Prototypes RIB can hold as retained objects, with their instances; the
// instances of any other are written as the copies they render like.
void write_instances(std::string& o, std::ostream& out, const Scene& scene, const std::vector<Material>& materials) {
  std::vector<WrittenPrototype> written;
  Scene rest;  // instances of prototypes RIB cannot hold
  for (size_t p = 0; p < scene.prototypes.size(); ++p) {
    written.push_back(prototype_state(scene.prototypes[p]));
    rest.prototypes.push_back(written.back().as_object ? Prototype{} : scene.prototypes[p]);
  }
  std::vector<bool> defined(scene.prototypes.size(), false);
  for (const Instance& inst : scene.instances) {
    const size_t p = size_t(inst.prototype);
    if (!written[p].as_object) {
      rest.instances.push_back(inst);
      continue;
    }
    const int handle = int(p) + 1;
    if (!defined[p]) {
      write_prototype(o, scene.prototypes[p], written[p], handle);
      defined[p] = true;
    }
    write_instance(o, inst, written[p], handle, materials, scene.material_programs);
    flush(out, o);
  }
  write_surfaces(o, out, with_instances_made_real(rest), materials, scene.material_programs);
}

// write_rib() after validation.
void write_valid_scene(const Scene& scene, std::ostream& out, const std::string& display_name,
                       const std::string& image_folder, const std::string& image_reference) {
  // A Scene without materials renders with Material{}: write that as material 0.
  std::vector<Material> materials = scene.materials;
  if (materials.empty()) materials.emplace_back();

  std::string o;
  o += "##RenderMan RIB\n# Written by Micropoly ";
  o += MICROPOLY_VERSION;
  o += "; the micropoly extensions are described in docs/rib.md.\nversion 3.04\n";
  write_options(o, scene.settings, scene.camera);
  write_images(o, scene.images, image_folder, image_reference);
  o += "FrameBegin 1\n";
  if (!display_name.empty()) {
    o += "Display ";
    put_string(o, display_name);
    o += " \"file\" \"rgba\"\n";
  }
  write_image_and_camera(o, scene);
  o += "WorldBegin\n";
  // Lights first, at the world's top level: on for every primitive, in order.
  for (size_t i = 0; i < scene.lights.size(); ++i) write_light(o, scene.lights[i], static_cast<int>(i) + 1);
  write_world(o, scene, image_folder, image_reference);
  // The material table, in index order (index 0 replaces the default surface).
  for (size_t i = 0; i < materials.size(); ++i) {
    o += "AttributeBegin\n";
    write_material(o, materials[i], static_cast<int>(i), "  ", scene.material_programs);
    o += "AttributeEnd\n";
  }
  flush(out, o);
  write_surfaces(o, out, scene, materials, scene.material_programs);
  write_instances(o, out, scene, materials);
  o += "WorldEnd\nFrameEnd\n";
  flush(out, o);
  out.flush();
  if (!out) throw Error("writing RIB failed (stream error)");
}

}  // namespace

void write_rib(const Scene& scene, std::ostream& out, const std::string& display_name,
               const std::string& image_folder) {
  validate_scene(scene);
  write_valid_scene(scene, out, display_name, image_folder, image_folder);
}

void write_rib_file(const Scene& scene, const std::string& path, const std::string& display_name) {
  validate_scene(scene);  // before the file is created or truncated
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) throw Error("cannot open '" + path + "' for writing: " + std::strerror(errno));
  try {
    // Textures beside the file, named relative to it: scene.rib -> scene_textures/.
    const std::filesystem::path rib(path);
    const std::string folder = rib.stem().string() + "_textures";
    write_valid_scene(scene, file, display_name, (rib.parent_path() / folder).string(), folder);
    file.close();
  } catch (const Error& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
  if (!file) throw Error("cannot write '" + path + "': " + std::strerror(errno));
}

}  // namespace mp
