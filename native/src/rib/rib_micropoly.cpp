// Micropoly's RIB extensions, all under the name "micropoly" so other
// renderers skip them (docs/rib.md, "Micropoly extensions"). They carry what
// standard RIB cannot say about a Scene, so that rib_writer.cpp's files read
// back into the same Scene:
//   Option "micropoly"     render settings without a RenderMan request
//   Attribute "micropoly"  the shading state as Scene material number i
//   "uniform integer micropoly:material"  per-face material numbers
//   "facevarying float[2] micropoly:uvK"  UV layer K of a mesh
//   "constant float[3] micropoly:texspacelocation" / "...size"  Generated space
// The light shaders' extensions (a light's size for soft shadows) are read
// with the lights, in rib_shading.cpp.
#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <string>

#include "io/texture_io.h"
#include "micropoly/error.h"
#include "rib/rib_file.h"
#include "geometry/mp_patch.h"
#include "rib/rib_parser.h"
#include "rib/rib_program_check.h"

namespace mp::rib {
namespace {

void warn_unknown(const ParamList& params, std::initializer_list<const char*> known,
                  const std::function<void(const std::string&)>& warn) {
  for (const Param& p : params.params()) {
    bool ok = false;
    for (const char* k : known) ok = ok || p.name == k;
    if (!ok) warn(p.name);
  }
}

// A string parameter that names one of `choices` (or is absent: `current`
// stays); any other value is an error that lists them.
template <typename T>
T string_choice(ArgReader& args, const ParamList& params, const char* name,
                std::initializer_list<std::pair<const char*, T>> choices, T current) {
  const std::string value = params.get_string(name, "");
  if (value.empty()) return current;
  std::string names;
  size_t k = 0;
  for (const auto& [text, choice] : choices) {
    if (value == text) return choice;
    names += std::string(k == 0 ? "" : k + 1 == choices.size() ? " or " : ", ") + "\"" + text + "\"";
    ++k;
  }
  args.fail("\"" + std::string(name) + "\" must be " + names + ", not \"" + value + "\"");
  return current;
}

}  // namespace

void Parser::micropoly_option(ArgReader& args, const ParamList& params) {
  if (params.find("imagefile")) return read_image_option(args, params);
  RenderSettings& s = result_.scene.settings;
  const std::string method = params.get_string("boundsplit", "");
  if (method == "bounded")
    s.bound_split = BoundSplitMethod::Bounded;
  else if (method == "breadth")
    s.bound_split = BoundSplitMethod::Breadth;
  else if (!method.empty())
    args.fail("\"boundsplit\" must be \"bounded\" or \"breadth\", not \"" + method + "\"");
  const float memory = params.get_float("boundsplitmemory", s.bound_split_memory_mib);
  if (!(memory > 0.0f)) args.fail("\"boundsplitmemory\" must be a positive number of MiB");
  s.bound_split_memory_mib = memory;
  // Grid size and split depth are clamped by the renderer; any int is kept.
  params.get_int("maxgridsize", INT_MIN, INT_MAX, &s.max_grid_size);
  params.get_int("maxsplitdepth", INT_MIN, INT_MAX, &s.max_split_depth);
  int flag = s.backface_culling ? 1 : 0;
  params.get_int("backfaceculling", 0, 1, &flag);
  s.backface_culling = flag != 0;
  flag = s.depth_and_normal_passes ? 1 : 0;
  params.get_int("depthandnormal", 0, 1, &flag);
  s.depth_and_normal_passes = flag != 0;
  // Shadow maps: on or off, their device memory and their shading rate.
  flag = s.shadows ? 1 : 0;
  params.get_int("shadows", 0, 1, &flag);
  s.shadows = flag != 0;
  flag = s.occlusion_culling ? 1 : 0;
  params.get_int("occlusionculling", 0, 1, &flag);
  s.occlusion_culling = flag != 0;
  flag = s.sample_culling ? 1 : 0;
  params.get_int("sampleculling", 0, 1, &flag);
  s.sample_culling = flag != 0;
  flag = s.holdout_covers ? 1 : 0;
  params.get_int("holdoutcovers", 0, 1, &flag);
  s.holdout_covers = flag != 0;
  auto positive = [](float v) { return v > 0.0f && std::isfinite(v); };
  s.sampler = string_choice(args, params, "sampler", {{"auto", Sampler::Auto}, {"tiles", Sampler::Tiles},
                                                       {"micropolygons", Sampler::Micropolygons}, {"bins", Sampler::Bins}},
                            s.sampler);
  params.get_int("boundsplitchain", 1, 1024, &s.bound_split_chain);
  params.get_int("boundsplitsteps", 0, 1024, &s.bound_split_steps);
  s.resolver = string_choice(args, params, "resolver",
                             {{"auto", Resolver::Auto}, {"tiles", Resolver::Tiles}, {"pixels", Resolver::Pixels}},
                             s.resolver);
  s.occlusion_waves = string_choice(args, params, "occlusionwaves",
                                    {{"auto", OcclusionWaves::Auto}, {"on", OcclusionWaves::On},
                                     {"off", OcclusionWaves::Off}},
                                    s.occlusion_waves);
  s.visibility_first = string_choice(args, params, "visibilityfirst",
                                     {{"auto", VisibilityFirst::Auto}, {"on", VisibilityFirst::On},
                                      {"off", VisibilityFirst::Off}},
                                     s.visibility_first);
  s.sample_memory_mib = params.get_float_checked("samplememory", s.sample_memory_mib, positive,
                                                 "a positive number of MiB");
  s.shadow_memory_mib = params.get_float_checked("shadowmemory", s.shadow_memory_mib, positive,
                                                 "a positive number of MiB");
  s.shadow_shading_rate = params.get_float_checked("shadowshadingrate", s.shadow_shading_rate, positive,
                                                   "a positive number");
  params.get_int("worldshadowdirections", 0, 64, &s.world_probes);
  s.texture_filter_width = params.get_float_checked(
      "texturefilterwidth", s.texture_filter_width, [](float v) { return v >= 0.0f && v <= 16.0f; }, "0 to 16");
  // Depth of field beyond RiDepthOfField: Cycles' aperture shape and the
  // coarser dicing of blurred surfaces.
  Camera& cam = result_.scene.camera;
  params.get_int("apertureblades", 0, Camera::kMaxApertureBlades, &cam.aperture_blades);
  cam.aperture_rotation = params.get_float_checked("aperturerotation", cam.aperture_rotation,
                                                   [](float v) { return std::isfinite(v); }, "a finite angle in radians");
  cam.aperture_ratio = params.get_float_checked("apertureratio", cam.aperture_ratio, positive, "a positive number");
  if (const Param* curve = params.find("shuttercurve")) {
    std::vector<float>& out = result_.scene.shutter_curve;
    out.clear();
    for (double v : curve->value->numbers) out.push_back(static_cast<float>(v));
  }
  s.dof_dice_factor = params.get_float_checked("focusfactor", s.dof_dice_factor,
                                               [](float v) { return v >= 0.0f && std::isfinite(v); }, "a number >= 0");
  const int line = args.request().line;
  warn_unknown(params,
               {"boundsplit", "boundsplitmemory", "maxgridsize", "maxsplitdepth", "backfaceculling",
                "depthandnormal", "shadows", "shadowmemory", "shadowshadingrate", "occlusionculling", "sampleculling",
                "holdoutcovers",
                "worldshadowdirections", "texturefilterwidth", "apertureblades", "aperturerotation", "apertureratio",
                "focusfactor", "shuttercurve", "sampler", "samplememory", "visibilityfirst", "resolver", "boundsplitchain", "occlusionwaves",
                "boundsplitsteps"},
               [&](const std::string& name) {
                 warn_once("option-micropoly:" + name, line,
                           "Option \"micropoly\": parameter \"" + name + "\" is ignored");
               });
}

void Parser::check_program(const std::string& source, const ParamList& params, const std::string& what) const {
  if (source.empty() || paths_.allows_any()) return;
  const std::string problem = program_source_problem(source);
  if (!problem.empty()) {
    const Param* p = params.find("program");
    throw RibError(where(p ? p->line : 0) + ": " + what + " refused: " + problem +
                   "; a scene file's program may not reach beyond the device (allow it with --allow-any-path)");
  }
}

// MakeTexture "picture" "texture" swrap twrap filter swidth twidth: what
// RenderMan's texture file would hold, every image here gets when the scene
// is uploaded (its MIP levels, kernels/textures/mp_tex_image.h), so the
// texture is its picture: a later image or map naming the texture reads the
// picture. Wrap modes and filter widths belong to each lookup here (the
// material program's Image Texture node), not to the file.
void Parser::req_make_texture(ArgReader& args) {
  const int line = args.request().line;
  const std::string picture = args.string(), texture = args.string();
  for (const std::string& wrap : {args.string(), args.string()})
    if (wrap != "periodic" && wrap != "clamp" && wrap != "black")
      args.fail("MakeTexture: a wrap mode is \"periodic\", \"clamp\" or \"black\", not \"" + wrap + "\"");
  args.string();  // the filter function: the levels are box-filtered whatever it names
  for (double width : args.numbers(2))
    if (!(width > 0.0)) args.fail("MakeTexture: filter widths must be positive");
  const ParamList params(args, decls_);
  warn_unknown(params, {}, [&](const std::string& name) {
    warn_once("maketexture:" + name, line, "MakeTexture: parameter \"" + name + "\" is ignored");
  });
  made_textures_[texture] = find_file(picture, true, line, "MakeTexture").open;
  warn_once("maketexture", line,
            "MakeTexture: \"" + texture + "\" reads \"" + picture +
                "\" with MIP levels built at render time; wrap modes and filter widths come from each lookup");
}

std::string Parser::texture_file(const std::string& name, int line, const std::string& request) const {
  const auto made = made_textures_.find(name);
  return made != made_textures_.end() ? made->second : find_file(name, true, line, request).open;
}

void Parser::read_image_option(ArgReader& args, const ParamList& params) {
  const int line = args.request().line;
  warn_unknown(params, {"image", "imagefile", "imagesrgb"}, [&](const std::string& name) {
    warn_once("option-micropoly-image:" + name, line,
              "Option \"micropoly\": parameter \"" + name + "\" is ignored with \"imagefile\"");
  });
  const std::string file = params.get_string("imagefile", "");
  if (file.empty()) args.fail("\"imagefile\" must name a texture file");
  const std::string path = texture_file(file, line, "Option \"micropoly\" \"imagefile\"");
  Image image;
  try {
    image = read_texture_image(path, Limits::kMaxTexels - texels_);
  } catch (const Error& e) {
    args.fail(e.what());
  }
  texels_ += image.pixels.size();
  image.name = params.get_string("image", file);
  // PNGs hold sRGB-encoded values and EXRs linear ones unless "imagesrgb" says otherwise.
  const std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : path;
  int srgb = ext == ".png" || ext == ".PNG" ? 1 : 0;
  params.get_int("imagesrgb", 0, 1, &srgb);
  image.srgb = srgb != 0;
  result_.scene.images.push_back(std::move(image));
}

void Parser::read_environment_light(ArgReader& args, const ParamList& params) {
  const int line = args.request().line;
  const std::string what = "LightSource \"micropoly_environmentlight\"";
  warn_unknown(params, {"program", "programname", "programparams", "mapname", "bakewidth", "camera", "diffuse",
                        "glossy", "shadowname", "intensity"},
               [&](const std::string& name) {
                 warn_once("envlight-param:" + name, line, what + ": parameter \"" + name + "\" is ignored");
               });
  World& world = result_.scene.world;
  if (world.present()) warn_once("envlight-twice", line, what + ": a second environment replaces the first");
  world = World{};
  const std::string source = params.get_string("program", ""), map = params.get_string("mapname", "");
  if (source.empty() == map.empty()) args.fail(what + " needs one of \"program\" and \"mapname\"");
  check_program(source, params, what + " \"program\"");
  if (!source.empty()) {
    // The world's node tree as a material program, shared like materials'.
    std::vector<MaterialProgram>& programs = result_.scene.material_programs;
    auto it = std::find_if(programs.begin(), programs.end(), [&](const MaterialProgram& p) { return p.source == source; });
    world.program = static_cast<int>(it - programs.begin());
    if (it == programs.end()) programs.push_back({params.get_string("programname", "world"), source});
    world.program_params = params.get_float_list("programparams");
    params.get_int("bakewidth", 8, 8192, &world.bake_width);
  } else {
    // An equirectangular map in world space (Cycles' convention, Z up).
    // Its radiance is the texture's times "intensity".
    const std::string path = texture_file(map, line, what + " \"mapname\"");
    Image image;
    try {
      image = read_texture_image(path, Limits::kMaxTexels - texels_);
    } catch (const Error& e) {
      args.fail(e.what());
    }
    texels_ += image.pixels.size();
    const float intensity = params.get_float("intensity", 1.0f);
    world.width = image.width, world.height = image.height;
    world.radiance.resize(image.pixels.size() * 4);
    for (size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 4; ++c) world.radiance[4 * i + size_t(c)] = image.pixels[i][c] * (c < 3 ? intensity : 1.0f);
  }
  int camera = 1;
  params.get_int("camera", 0, 1, &camera);
  world.camera = camera != 0;
  auto unit = [](float v) { return v >= 0.0f && v <= 1.0f; };
  world.diffuse = params.get_float_checked("diffuse", 1.0f, unit, "a number in [0, 1]");
  world.glossy = params.get_float_checked("glossy", 1.0f, unit, "a number in [0, 1]");
  // As for the other lights: "shadowname" names where shadows come from; an
  // empty one (or none) leaves the world's light unshadowed.
  world.cast_shadows = !params.get_string("shadowname", "").empty();
}

void Parser::micropoly_attribute(ArgReader& args, const ParamList& params) {
  const int line = args.request().line;
  warn_unknown(params, {"material", "materialname", "program", "programparams", "programdisplaces", "programshades",
                        "programalpha", "displacementbound", "displacementworld", "objectcolor", "objectalpha",
                        "objectindex", "objectrandom", "objectattributes", "roundu", "ribbons"}, [&](const std::string& name) {
    warn_once("attribute-micropoly:" + name, line,
              "Attribute \"micropoly\": parameter \"" + name + "\" is ignored");
  });
  // Patches whose u runs around a round section (hair tubes written back).
  if (params.find("roundu")) {
    int round = 0;
    params.get_int("roundu", 0, 1, &round);
    attrs_.round_u = round != 0;
  }
  // Patches that are ribbons' strand segments (ribbons written back).
  if (params.find("ribbons")) {
    int ribbons = 0;
    params.get_int("ribbons", 0, 1, &ribbons);
    attrs_.ribbons = ribbons != 0;
  }
  // What Object Info reads of the following objects.
  ObjectInfo& info = attrs_.object_info;
  glm::vec3 rgb(info.color);
  params.get_floats("objectcolor", &rgb.x, 3);
  auto finite = [](float v) { return std::isfinite(v); };
  info.color = glm::vec4(rgb, params.get_float_checked("objectalpha", info.color.w, finite, "a finite number"));
  info.pass_index = params.get_float_checked("objectindex", info.pass_index, finite, "a finite number");
  info.random = params.get_float_checked("objectrandom", info.random,
                                         [](float v) { return v >= 0.0f && v <= 1.0f; }, "a number in [0, 1]");
  // Attribute nodes' per-object values (ObjectInfo::attributes): RGBA per slot.
  if (params.find("objectattributes")) {
    const std::vector<float> a = params.get_float_list("objectattributes");
    if (a.size() % 4 != 0)
      args.fail_at(line, "Attribute \"micropoly\": \"objectattributes\" needs four numbers (RGBA) per slot");
    info.attributes.clear();
    for (size_t k = 0; k + 3 < a.size(); k += 4) info.attributes.emplace_back(a[k], a[k + 1], a[k + 2], a[k + 3]);
  }
  if (!params.find("material")) {
    if (params.find("materialname"))
      warn_once("attribute-micropoly:materialname", line,
                "Attribute \"micropoly\": \"materialname\" without \"material\" is ignored");
    return;
  }
  // Materials are numbered densely: an index may replace an existing
  // material (0 replaces the default surface) or add the next one.
  const long long count = static_cast<long long>(result_.scene.materials.size());
  int index = 0;
  params.get_int("material", 0, std::min<long long>(count, INT_MAX), &index);
  // A material program (node tree as OpenCL C), shared by identical sources.
  MaterialProgramUse use;
  const std::string source = params.get_string("program", "");
  check_program(source, params, "Attribute \"micropoly\" \"program\"");
  if (!source.empty()) {
    std::vector<MaterialProgram>& programs = result_.scene.material_programs;
    auto it = std::find_if(programs.begin(), programs.end(), [&](const MaterialProgram& p) { return p.source == source; });
    use.program = static_cast<int>(it - programs.begin());
    if (it == programs.end()) programs.push_back({params.get_string("materialname", "material program"), source});
    int flag = 0;
    params.get_int("programdisplaces", 0, 1, &flag);
    use.displaces = flag != 0;
    flag = 0;
    params.get_int("programshades", 0, 1, &flag);
    use.shades = flag != 0;
    flag = 0;
    params.get_int("programalpha", 0, 2, &flag);  // 2: a hard cut (Material::program_alpha_cut)
    use.alpha = flag != 0;
    use.alpha_cut = flag == 2;
    use.params = params.get_float_list("programparams");
    use.displacement_bound = params.get_float("displacementbound", 0.0f);
    flag = 0;
    params.get_int("displacementworld", 0, 1, &flag);
    use.displacement_world = flag != 0;
    if (!(use.displacement_bound >= 0.0f)) args.fail("\"displacementbound\" must be a non-negative number");
  }
  define_material(index, params.get_string("materialname", attrs_.surface.name), use);
}

void Parser::define_material(int index, const std::string& name, const MaterialProgramUse& use) {
  // The current shading state becomes material `index` and is selected for
  // the following primitives of the attribute block. Redefining a material
  // changes it for every primitive that uses it (the writer always repeats
  // the same state).
  Material m = attrs_.surface;
  m.color = attrs_.color;
  m.opacity = attrs_.opacity;
  m.name = name;
  m.program = use.program;
  m.program_displaces = use.displaces;
  m.program_shades = use.shades;
  m.program_alpha = use.alpha;
  m.program_alpha_cut = use.alpha_cut;
  m.program_params = use.params;
  m.displacement_bound = use.displacement_bound;
  m.displacement_bound_world = use.displacement_world;
  std::vector<Material>& materials = result_.scene.materials;
  const size_t i = static_cast<size_t>(index);
  if (i == materials.size()) {
    materials.push_back(m);
  } else {
    // Shading states that led to the old material must not find it any more.
    auto it = material_keys_.find(material_key(materials[i]));
    if (it != material_keys_.end() && it->second == index) material_keys_.erase(it);
    materials[i] = m;
  }
  material_keys_.emplace(material_key(m), index);  // keeps an earlier equal material
  attrs_.material_slot = index;
}

void Parser::read_face_materials(ArgReader& args, const ParamList& params, size_t faces,
                                 std::vector<int>* out) const {
  out->clear();
  const Param* p = params.find("micropoly:material");
  if (!p) return;
  if (p->decl.is_string() || p->value->numbers.size() != faces)
    args.fail_at(p->line, "\"micropoly:material\" needs one material index per face (" +
                              std::to_string(faces) + "), found " + std::to_string(p->value->size()) +
                              " values");
  const long long count = static_cast<long long>(result_.scene.materials.size());
  *out = args.int_array(*p->value, 0, count - 1, "micropoly:material");
}

void Parser::read_patch_primvars(ArgReader& args, const ParamList& params, Primitive* prim) const {
  prim->patch_uvs.clear();
  for (int k = 0; k < MP_MAX_UV_LAYERS; ++k) {
    const std::string name = "micropoly:uv" + std::to_string(k);
    const Param* p = params.find(name);
    if (!p) {
      prim->patch_uvs.emplace_back(4, glm::vec2(0.0f));  // a gap reads zeros
      continue;
    }
    const std::vector<double>& v = p->value->numbers;
    if (p->decl.is_string() || p->decl.components() != 2 || v.size() != 8)
      args.fail_at(p->line, "\"" + name + "\" needs two floats at each of the patch's 4 corners, found " +
                                std::to_string(v.size()) + " values");
    auto at = [&](int i) { return glm::vec2(static_cast<float>(v[size_t(2 * i)]), static_cast<float>(v[size_t(2 * i + 1)])); };
    // RenderMan's (u0 v0), (u1 v0), (u0 v1), (u1 v1) -> (0,0), (1,0), (1,1), (0,1).
    prim->patch_uvs.push_back({at(0), at(1), at(3), at(2)});
  }
  // Layers are numbered densely: the zeros past the last given one go.
  while (!prim->patch_uvs.empty() &&
         !params.find("micropoly:uv" + std::to_string(prim->patch_uvs.size() - 1)))
    prim->patch_uvs.pop_back();
}

void Parser::read_mesh_primvars(ArgReader& args, const ParamList& params, const std::vector<int>& corners,
                                 size_t npoints, Mesh* mesh) const {
  mesh->uv_layers.clear();
  for (int k = 0; k < MP_MAX_UV_LAYERS; ++k) {
    const std::string name = "micropoly:uv" + std::to_string(k);
    const Param* p = params.find(name);
    if (!p) {
      // Layers are numbered densely; a gap reads zeros, as a missing layer does.
      bool later = false;
      for (int j = k + 1; j < MP_MAX_UV_LAYERS; ++j) later = later || params.find("micropoly:uv" + std::to_string(j));
      if (!later) break;
      mesh->uv_layers.emplace_back(corners.size(), glm::vec2(0.0f));
      continue;
    }
    const bool per_corner = p->decl.cls == VarClass::FaceVarying || p->decl.cls == VarClass::FaceVertex;
    const bool per_vertex = p->decl.cls == VarClass::Vertex || p->decl.cls == VarClass::Varying;
    const size_t expect = per_corner ? corners.size() : npoints;
    const std::vector<double>& v = p->value->numbers;
    if (p->decl.is_string() || p->decl.components() != 2 || !(per_corner || per_vertex) || v.size() != 2 * expect)
      args.fail_at(p->line, "\"" + name + "\" needs two floats per face corner (facevarying, " +
                                std::to_string(corners.size()) + ") or per vertex (vertex, " +
                                std::to_string(npoints) + "), found " + std::to_string(v.size()) + " values");
    std::vector<glm::vec2> layer(corners.size());
    for (size_t c = 0; c < corners.size(); ++c) {
      const size_t i = per_corner ? c : static_cast<size_t>(corners[c]);
      layer[c] = glm::vec2(static_cast<float>(v[2 * i]), static_cast<float>(v[2 * i + 1]));
    }
    mesh->uv_layers.push_back(std::move(layer));
  }
  // Shading normals: RenderMan's "N" (vertex normals, or per face corner).
  mesh->corner_normals.clear();
  if (const Param* p = params.find("N")) {
    const bool per_corner = p->decl.cls == VarClass::FaceVarying || p->decl.cls == VarClass::FaceVertex;
    const size_t expect = per_corner ? corners.size() : npoints;
    const std::vector<double>& v = p->value->numbers;
    if (p->decl.is_string() || p->decl.components() != 3 || p->decl.cls == VarClass::Constant ||
        p->decl.cls == VarClass::Uniform || v.size() != 3 * expect)
      args.fail_at(p->line, "\"N\" needs one normal per vertex (" + std::to_string(npoints) +
                                ") or per face corner (facevarying, " + std::to_string(corners.size()) + "), found " +
                                std::to_string(v.size()) + " values");
    mesh->corner_normals.resize(corners.size());
    for (size_t c = 0; c < corners.size(); ++c) {
      const size_t i = per_corner ? c : static_cast<size_t>(corners[c]);
      mesh->corner_normals[c] = glm::vec3(float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2]));
    }
  }
  const char* space[] = {"micropoly:texspacelocation", "micropoly:texspacesize"};
  glm::vec3* out[] = {&mesh->texspace_location, &mesh->texspace_size};
  for (int i = 0; i < 2; ++i) {
    const Param* p = params.find(space[i]);
    if (!p) continue;
    if (p->decl.is_string() || p->value->numbers.size() != 3)
      args.fail_at(p->line, std::string("\"") + space[i] + "\" needs three floats");
    const std::vector<double>& v = p->value->numbers;
    *out[i] = glm::vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
  }
}

}  // namespace mp::rib
