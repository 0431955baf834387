// Request dispatch, block structure, options and camera requests.
#include "rib/rib_parser.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "rib/rib_file.h"

namespace mp::rib {

size_t Primitive::elements() const {
  if (kind == Kind::Patches) return patch_points.size();
  size_t uvs = 0;
  for (const auto& layer : mesh.uv_layers) uvs += layer.size();
  return mesh.points.size() + mesh.face_vertex_indices.size() + mesh.face_vertex_counts.size() + uvs;
}

Parser::Parser(const std::string& scene_dir, const RibReadOptions& options) : paths_(scene_dir, options) {
  // RenderMan's defaults where they differ from the Scene's (RI spec 3.2,
  // tables 4.1 and 4.2): 640x480, PixelSamples 2 2, gaussian 2x2, fov 90.
  RenderSettings& s = result_.scene.settings;
  s.width = 640;
  s.height = 480;
  s.pixel_aspect = 1.0f;
  s.samples_x = s.samples_y = 2;
  s.filter = PixelFilter::Gaussian;
  s.filter_width = 2.0f;
  s.shading_rate = 1.0f;
  Camera& c = result_.scene.camera;
  c.projection = Camera::Projection::Perspective;
  c.fov_degrees = 90.0f;
  c.screen_left = c.screen_right = c.screen_bottom = c.screen_top = 0.0f;

  // RenderMan's default surface ("defaultsurface", a headlight-lit matte) is
  // approximated by matte with Ka = Kd = 1; it is always material 0.
  Material def;
  def.name = "defaultsurface";
  def.model = Material::Model::Matte;
  def.ka = 1.0f;
  def.kd = 1.0f;
  def.ks = 0.0f;
  attrs_.surface = def;
  attrs_.ubasis = attrs_.vbasis = bezier_basis();
  result_.scene.materials.clear();
  material_index(attrs_);
}

const std::unordered_map<std::string, Parser::Handler>& Parser::handlers() {
  static const std::unordered_map<std::string, Handler> table = {
      {"version", &Parser::req_version},
      {"FrameBegin", &Parser::req_frame_begin},
      {"FrameEnd", &Parser::req_frame_end},
      {"WorldBegin", &Parser::req_world_begin},
      {"WorldEnd", &Parser::req_world_end},
      {"AttributeBegin", &Parser::req_attribute_begin},
      {"AttributeEnd", &Parser::req_attribute_end},
      {"TransformBegin", &Parser::req_transform_begin},
      {"TransformEnd", &Parser::req_transform_end},
      {"SolidBegin", &Parser::req_solid_begin},
      {"SolidEnd", &Parser::req_solid_end},
      {"MotionBegin", &Parser::req_motion_begin},
      {"Shutter", &Parser::req_shutter},
      {"MotionEnd", &Parser::req_motion_end},
      {"Format", &Parser::req_format},
      {"Projection", &Parser::req_projection},
      {"ScreenWindow", &Parser::req_screen_window},
      {"CropWindow", &Parser::req_crop_window},
      {"Clipping", &Parser::req_clipping},
      {"DepthOfField", &Parser::req_depth_of_field},
      {"PixelSamples", &Parser::req_pixel_samples},
      {"PixelFilter", &Parser::req_pixel_filter},
      {"ShadingRate", &Parser::req_shading_rate},
      {"Display", &Parser::req_display},
      {"Option", &Parser::req_option},
      {"Attribute", &Parser::req_attribute},
      {"Declare", &Parser::req_declare},
      {"ReadArchive", &Parser::req_read_archive},
      {"Bound", &Parser::req_ignore},         // a culling hint; bounds are computed
      {"ErrorHandler", &Parser::req_ignore},  // errors always throw RibError
      {"Identity", &Parser::req_identity},
      {"Transform", &Parser::req_transform},
      {"ConcatTransform", &Parser::req_concat_transform},
      {"Translate", &Parser::req_translate},
      {"Rotate", &Parser::req_rotate},
      {"Scale", &Parser::req_scale},
      {"CoordinateSystem", &Parser::req_coordinate_system},
      {"CoordSysTransform", &Parser::req_coord_sys_transform},
      {"Orientation", &Parser::req_orientation},
      {"ReverseOrientation", &Parser::req_reverse_orientation},
      {"Sides", &Parser::req_sides},
      {"Color", &Parser::req_color},
      {"Opacity", &Parser::req_opacity},
      {"Surface", &Parser::req_surface},
      {"LightSource", &Parser::req_light_source},
      {"Illuminate", &Parser::req_illuminate},
      {"Polygon", &Parser::req_polygon},
      {"GeneralPolygon", &Parser::req_general_polygon},
      {"PointsPolygons", &Parser::req_points_polygons},
      {"PointsGeneralPolygons", &Parser::req_points_general_polygons},
      {"SubdivisionMesh", &Parser::req_subdivision_mesh},
      {"Patch", &Parser::req_patch},
      {"PatchMesh", &Parser::req_patch_mesh},
      {"Sphere", &Parser::req_quadric},
      {"Cylinder", &Parser::req_quadric},
      {"Cone", &Parser::req_quadric},
      {"Disk", &Parser::req_quadric},
      {"Paraboloid", &Parser::req_quadric},
      {"Hyperboloid", &Parser::req_quadric},
      {"Torus", &Parser::req_quadric},
      {"Points", &Parser::req_points},
      {"Curves", &Parser::req_curves},
      {"NuPatch", &Parser::req_nupatch},
      {"Basis", &Parser::req_basis},
      {"ObjectBegin", &Parser::req_object_begin},
      {"ObjectEnd", &Parser::req_object_end},
      {"ObjectInstance", &Parser::req_object_instance},
      {"MakeTexture", &Parser::req_make_texture},
  };
  return table;
}

void Parser::parse(std::string_view text, const std::string& file, const std::string& base_dir,
                   int depth) {
  const Source src{&file, &base_dir, depth};
  const Source* outer = source_;
  source_ = &src;
  Lexer lexer(text, file);
  RequestReader reader(lexer);
  Request req;
  while (reader.next(req)) execute(req);
  source_ = outer;
}

void Parser::execute(const Request& req) {
  if (skipping_) return;  // later frames are tokenized (syntax-checked) only
  if (motion_depth_ > 0) {
    // A motion block's requests are collected and run together at MotionEnd.
    if (req.name == "MotionEnd") {
      motion_depth_ = 0;
      run_motion_block(req.line);
      return;
    }
    if (req.name == "MotionBegin") fail(req.line, "MotionBegin: nested motion blocks");
    motion_requests_.push_back(req);
    return;
  }
  // A transformation after a moving one moves every step's alike.
  static const std::unordered_set<std::string> kTransforms = {"Translate", "Rotate", "Scale", "ConcatTransform",
                                                              "Transform", "Identity", "CoordSysTransform"};
  if (!attrs_.motion_ctm.empty() && kTransforms.count(req.name)) {
    const glm::mat4 centre = attrs_.ctm;
    std::vector<glm::mat4> steps = attrs_.motion_ctm;
    for (glm::mat4& m : steps) {
      attrs_.ctm = m;
      run_handler(req);
      m = attrs_.ctm;
    }
    attrs_.ctm = centre;
    run_handler(req);
    attrs_.motion_ctm = steps;
    return;
  }
  run_handler(req);
}

void Parser::run_handler(const Request& req) {
  const auto& table = handlers();
  auto it = table.find(req.name);
  if (it == table.end()) {
    warn_once("request:" + req.name, req.line,
              "unsupported request '" + req.name + "' ignored (with its arguments)");
    return;
  }
  ArgReader args(req, *source_->file);
  (this->*(it->second))(args);
}

std::string Parser::where(int line) const {
  return (source_ ? *source_->file : std::string("<rib>")) + ":" + std::to_string(line);
}

void Parser::warn(int line, const std::string& message) {
  result_.warnings.push_back(where(line) + ": " + message);
}

void Parser::warn_once(const std::string& key, int line, const std::string& message) {
  if (warned_.insert(key).second) warn(line, message);
}

void Parser::fail(int line, const std::string& reason) const {
  throw RibError(where(line) + ": " + reason);
}

void Parser::charge(size_t elements, int line) {
  elements_ += elements;
  if (elements_ > Limits::kMaxSceneElements)
    fail(line, "scene too large: more than " + std::to_string(Limits::kMaxSceneElements) +
                   " points and indices in total");
}

const char* Parser::block_name(Block::Kind kind) {
  switch (kind) {
    case Block::Kind::Frame: return "FrameBegin";
    case Block::Kind::World: return "WorldBegin";
    case Block::Kind::Attribute: return "AttributeBegin";
    case Block::Kind::Transform: return "TransformBegin";
    case Block::Kind::Object: return "ObjectBegin";
    case Block::Kind::Solid: return "SolidBegin";
  }
  return "Begin";
}

void Parser::push_block(Block::Kind kind, int line) {
  if (blocks_.size() >= Limits::kMaxBlockDepth)
    fail(line, std::string(block_name(kind)) + ": blocks nested deeper than " +
                   std::to_string(Limits::kMaxBlockDepth));
  blocks_.push_back(Block{kind, line, *source_->file, attrs_});
}

void Parser::pop_block(Block::Kind kind, ArgReader& args) {
  args.done();
  if (blocks_.empty() || blocks_.back().kind != kind) {
    std::string why = std::string("without a matching ") + block_name(kind);
    if (!blocks_.empty())
      why += " (the innermost open block is " + std::string(block_name(blocks_.back().kind)) +
             " at " + blocks_.back().file + ":" + std::to_string(blocks_.back().line) + ")";
    args.fail(why);
  }
  // All blocks but TransformBegin/End save and restore the attributes
  // (RI spec 3.2, section 4); TransformEnd restores only the transformation.
  if (kind == Block::Kind::Transform)
    attrs_.ctm = blocks_.back().saved.ctm;
  else
    attrs_ = std::move(blocks_.back().saved);
  blocks_.pop_back();
}

std::string Parser::handle_key(ArgReader& args) {
  // Handles are sequence numbers in RIB 3.2 and may be strings in later RIB.
  const Arg& a = args.any();
  if (a.kind == Arg::Kind::Number) {
    int n = 0;
    if (!to_int(a.numbers[0], -2147483647LL - 1, 2147483647LL, &n))
      args.fail_at(a.line, "a numeric handle must be an integer");
    return "#" + std::to_string(n);
  }
  if (a.kind == Arg::Kind::String) return "\"" + a.strings[0] + "\"";
  args.fail_at(a.line, std::string("expected a handle (a number or a string), found ") + a.describe());
}

bool Parser::current_frame_is_left_handed() const {
  // Camera space is left-handed; the current coordinate system is too unless
  // the transformation to camera space mirrors (negative determinant).
  const glm::mat4 full = in_world_ ? camera_ * attrs_.ctm : attrs_.ctm;
  return glm::determinant(glm::mat3(full)) > 0.0f;
}

const glm::mat4& Parser::camera_inverse(int line) {
  if (!camera_inv_valid_) fail(line, "the camera transformation is not known yet");
  return camera_inv_;
}

// --- structure ------------------------------------------------------------------

void Parser::req_version(ArgReader&) {}
void Parser::req_ignore(ArgReader&) {}

void Parser::req_frame_begin(ArgReader& args) {
  if (world_done_) {
    warn_once("frames", args.request().line,
              "only the first frame is rendered; later frames are ignored");
    skipping_ = true;
    return;
  }
  if (!args.at_end()) args.integer(-2147483647LL - 1, 2147483647LL);
  args.done();
  for (const Block& b : blocks_)
    if (b.kind == Block::Kind::Frame || b.kind == Block::Kind::World)
      args.fail(std::string("FrameBegin inside ") + block_name(b.kind) + " at line " +
                std::to_string(b.line));
  push_block(Block::Kind::Frame, args.request().line);
}

void Parser::req_frame_end(ArgReader& args) { pop_block(Block::Kind::Frame, args); }

void Parser::req_world_begin(ArgReader& args) {
  const int line = args.request().line;
  if (world_done_) {
    warn_once("frames", line, "only the first frame is rendered; later frames are ignored");
    skipping_ = true;
    return;
  }
  args.done();
  if (in_world_) args.fail("nested WorldBegin");
  if (defining_active_) args.fail("WorldBegin inside an object definition");
  // The current transformation at WorldBegin is the world-to-camera transform.
  camera_ = attrs_.ctm;
  const float det = glm::determinant(camera_);
  if (!std::isfinite(det) || std::fabs(det) < 1e-30f)
    args.fail("the camera transformation is singular");
  camera_inv_ = glm::inverse(camera_);
  camera_inv_valid_ = true;
  // RenderMan camera space is left-handed (+z forward); Micropoly's is
  // right-handed looking down -z: mirror z.
  const glm::mat4 mirror_z(glm::vec4(1, 0, 0, 0), glm::vec4(0, 1, 0, 0), glm::vec4(0, 0, -1, 0),
                           glm::vec4(0, 0, 0, 1));
  result_.scene.camera.world_to_camera = mirror_z * camera_;
  // A camera that moves: its transformation at each motion step.
  result_.scene.camera.motion_world_to_camera.clear();
  for (const glm::mat4& m : attrs_.motion_ctm) result_.scene.camera.motion_world_to_camera.push_back(mirror_z * m);
  push_block(Block::Kind::World, line);
  attrs_.ctm = glm::mat4(1.0f);
  attrs_.motion_ctm.clear();
  in_world_ = true;
  convert_camera_lights(line);
}

void Parser::req_world_end(ArgReader& args) {
  pop_block(Block::Kind::World, args);
  in_world_ = false;
  world_done_ = true;
  has_merge_target_ = false;
}

// An attribute block is a separate object: Polygon/Patch runs do not merge
// across its boundaries (the writer relies on this to keep patch sets apart).
void Parser::req_attribute_begin(ArgReader& args) {
  args.done();
  push_block(Block::Kind::Attribute, args.request().line);
  has_merge_target_ = false;
}
void Parser::req_attribute_end(ArgReader& args) {
  pop_block(Block::Kind::Attribute, args);
  has_merge_target_ = false;
}

void Parser::req_transform_begin(ArgReader& args) {
  args.done();
  push_block(Block::Kind::Transform, args.request().line);
}
void Parser::req_transform_end(ArgReader& args) { pop_block(Block::Kind::Transform, args); }

void Parser::req_solid_begin(ArgReader& args) {
  args.string();
  args.done();
  warn_once("request:SolidBegin", args.request().line,
            "SolidBegin: solid operations are not supported; the primitives are rendered as is");
  push_block(Block::Kind::Solid, args.request().line);
}
void Parser::req_solid_end(ArgReader& args) { pop_block(Block::Kind::Solid, args); }

void Parser::req_motion_end(ArgReader& args) {
  // Inside a motion block execute() consumes MotionEnd; here it is unmatched.
  args.fail("without a matching MotionBegin");
}

// MotionBegin [times] ... MotionEnd: one request per time, all of one kind.
// The Scene's motion steps are evenly spread over the shutter, so the times
// must be too (from its opening to its closing), and every block must have
// as many as the first; otherwise the block's first request stands for it.
// Transformations give each step its own current transformation (and the
// camera's at WorldBegin); meshes (PointsPolygons, SubdivisionMesh, Polygon,
// GeneralPolygon, PointsGeneralPolygons) give their points per step, the same
// topology each time. The shutter centre's state is the middle step (the
// mean of the two middle ones for an even count).
void Parser::req_motion_begin(ArgReader& args) {
  const Arg& times = args.number_array();
  args.done();
  motion_times_.assign(times.numbers.begin(), times.numbers.end());
  if (motion_times_.empty()) args.fail("needs at least one time");
  motion_requests_.clear();
  motion_line_ = args.request().line;
  motion_depth_ = 1;
}

void Parser::req_shutter(ArgReader& args) {
  const double open = args.number(), close = args.number();
  args.done();
  if (!std::isfinite(open) || !std::isfinite(close) || close < open) args.fail("needs open <= close");
  shutter_open_ = open, shutter_close_ = close;
  shutter_set_ = true;
}

bool Parser::motion_usable(int line) {
  const size_t n = motion_times_.size();
  if (n < 2) return false;
  if (!shutter_set_) {
    shutter_open_ = motion_times_.front(), shutter_close_ = motion_times_.back();
    shutter_set_ = true;
  }
  const double span = shutter_close_ - shutter_open_;
  bool even = span > 0.0 && n <= size_t(kMaxMotionSteps);
  for (size_t k = 0; k < n && even; ++k)
    even = std::fabs(motion_times_[k] - (shutter_open_ + span * double(k) / double(n - 1))) <= 1e-4 * span;
  int& steps = result_.scene.motion_steps;
  if (even && steps != 0 && steps != int(n)) even = false;
  if (!even) {
    warn_once("motion-times", line,
              "MotionBegin: times must be 2 to " + std::to_string(kMaxMotionSteps) +
                  " evenly spread from the Shutter's opening to its closing, as many in every block; this "
                  "block's first request is used");
    return false;
  }
  steps = int(n);
  return true;
}

void Parser::run_motion_block(int line) {
  const size_t n = motion_times_.size();
  if (motion_requests_.size() != n)
    fail(motion_line_, "MotionBegin: " + std::to_string(n) + " times but " + std::to_string(motion_requests_.size()) +
                           " requests before MotionEnd");
  for (const Request& r : motion_requests_)
    if (r.name != motion_requests_[0].name)
      fail(r.line, "MotionBegin: a motion block's requests must be of one kind (" + motion_requests_[0].name +
                       ", then " + r.name + ")");
  const std::vector<Request> requests = std::move(motion_requests_);
  motion_requests_.clear();
  static const std::unordered_set<std::string> kTransforms = {"Translate", "Rotate", "Scale", "ConcatTransform",
                                                              "Transform"};
  static const std::unordered_set<std::string> kMeshes = {"PointsPolygons", "SubdivisionMesh", "Polygon",
                                                          "GeneralPolygon", "PointsGeneralPolygons"};
  const std::string& kind = requests[0].name;
  const bool transform = kTransforms.count(kind) > 0, mesh = kMeshes.count(kind) > 0 && in_world_ && !defining_active_;
  if (!(transform || mesh)) {
    warn_once("motion-kind:" + kind, line, "MotionBegin: " + kind + " does not move here; its first request is used");
    run_handler(requests[0]);
    return;
  }
  if (!motion_usable(line)) {
    execute(requests[0]);
    return;
  }
  if (transform) {
    std::vector<glm::mat4> steps(n);
    for (size_t k = 0; k < n; ++k) {
      attrs_.ctm = attrs_.motion_ctm.empty() ? attrs_.ctm : attrs_.motion_ctm[k];
      const glm::mat4 before = attrs_.ctm;
      run_handler(requests[k]);
      steps[k] = attrs_.ctm;
      attrs_.ctm = before;
    }
    attrs_.motion_ctm = steps;
    attrs_.ctm = n % 2 ? steps[n / 2] : 0.5f * (steps[n / 2 - 1] + steps[n / 2]);
    return;
  }
  // Meshes: each request adds its own; the last keeps every step's points.
  std::vector<std::vector<glm::vec3>> points;
  std::vector<int> counts, indices;
  Scene& scene = result_.scene;
  for (size_t k = 0; k < n; ++k) {
    has_merge_target_ = false;
    const size_t before = scene.meshes.size();
    execute(requests[k]);
    if (scene.meshes.size() != before + 1) fail(requests[k].line, "MotionBegin: the request made no mesh");
    const Mesh& made = scene.meshes.back();
    if (k == 0) {
      counts = made.face_vertex_counts, indices = made.face_vertex_indices;
    } else if (made.face_vertex_counts != counts || made.face_vertex_indices != indices ||
               made.points.size() != points[0].size()) {
      fail(requests[k].line, "MotionBegin: a mesh's topology must stay the same at every time");
    }
    points.push_back(made.points);
    if (k + 1 < n) scene.meshes.pop_back();
  }
  has_merge_target_ = false;
  Mesh& m = scene.meshes.back();
  m.motion_points = points;
  if (n % 2 == 0)
    for (size_t i = 0; i < m.points.size(); ++i) m.points[i] = 0.5f * (points[n / 2 - 1][i] + points[n / 2][i]);
  else
    m.points = points[n / 2];
}

// --- options and camera -----------------------------------------------------------

void Parser::req_format(ArgReader& args) {
  RenderSettings& s = result_.scene.settings;
  s.width = args.integer(1, Limits::kMaxResolution);
  s.height = args.integer(1, Limits::kMaxResolution);
  const double aspect = args.number();
  args.done();
  // A non-positive pixel aspect ratio asks for the default (square pixels).
  s.pixel_aspect = aspect > 0 ? static_cast<float>(aspect) : 1.0f;
}

void Parser::req_projection(ArgReader& args) {
  if (in_world_) args.fail("Projection inside the world block");
  const std::string name = args.string();
  ParamList params(args, decls_);
  Camera& cam = result_.scene.camera;
  if (name == "perspective") {
    const float fov = params.get_float("fov", 90.0f);
    if (!(fov > 0.0f && fov < 180.0f)) args.fail("fov must be in (0, 180) degrees");
    cam.projection = Camera::Projection::Perspective;
    cam.fov_degrees = fov;
  } else if (name == "orthographic") {
    cam.projection = Camera::Projection::Orthographic;
  } else {
    warn_once("projection:" + name, args.request().line,
              "Projection \"" + name + "\" is not supported; using perspective");
    cam.projection = Camera::Projection::Perspective;
  }
  // RiProjection defines camera space at the current transformation and
  // resets it to the identity; a transformation before it (which would
  // distort screen space) is not supported.
  if (attrs_.ctm != glm::mat4(1.0f))
    warn_once("pre-projection", args.request().line,
              "transformations before Projection are ignored");
  attrs_.ctm = glm::mat4(1.0f);
}

void Parser::req_screen_window(ArgReader& args) {
  const std::vector<double> w = args.numbers(4);
  args.done();
  if (w[0] == w[1] || w[2] == w[3]) args.fail("empty screen window");
  Camera& c = result_.scene.camera;
  c.screen_left = static_cast<float>(w[0]);
  c.screen_right = static_cast<float>(w[1]);
  c.screen_bottom = static_cast<float>(w[2]);
  c.screen_top = static_cast<float>(w[3]);
}

void Parser::req_crop_window(ArgReader& args) {
  std::vector<double> w = args.numbers(4);
  args.done();
  for (double& v : w) v = std::min(1.0, std::max(0.0, v));  // clamped to [0,1] (RI spec)
  if (!(w[0] < w[1]) || !(w[2] < w[3])) args.fail("empty crop window");
  RenderSettings& s = result_.scene.settings;
  s.crop_x0 = static_cast<float>(w[0]);
  s.crop_x1 = static_cast<float>(w[1]);
  s.crop_y0 = static_cast<float>(w[2]);
  s.crop_y1 = static_cast<float>(w[3]);
}

void Parser::req_clipping(ArgReader& args) {
  const double near_z = args.number();
  const double far_z = args.number();
  args.done();
  if (!(near_z > 0.0) || !(far_z > near_z)) args.fail("needs 0 < near < far");
  result_.scene.camera.clip_near = static_cast<float>(near_z);
  result_.scene.camera.clip_far = static_cast<float>(far_z);
}

// DepthOfField fstop focallength focaldistance: a thin lens of radius
// focallength / (2 fstop) in camera units, focused at focaldistance
// (RenderMan's RiDepthOfField); no arguments, or an infinite f-stop, is a
// pinhole. The aperture's shape comes from Option "micropoly".
void Parser::req_depth_of_field(ArgReader& args) {
  Camera& cam = result_.scene.camera;
  if (args.at_end()) {
    cam.lens_radius = 0.0f;
    return;
  }
  const std::vector<double> v = args.numbers(3);
  args.done();
  const double fstop = v[0], focal = v[1], focus = v[2];
  if (!(fstop > 0.0) || !(focal >= 0.0) || !std::isfinite(focal) || !(focus > 0.0) || !std::isfinite(focus))
    args.fail("needs fstop > 0, focallength >= 0 and focaldistance > 0");
  cam.lens_radius = std::isfinite(fstop) ? static_cast<float>(focal / (2.0 * fstop)) : 0.0f;
  cam.focus_distance = static_cast<float>(focus);
}

void Parser::req_pixel_samples(ArgReader& args) {
  const double xs = args.number();
  const double ys = args.number();
  args.done();
  auto count = [&](double v) {
    if (v > Limits::kMaxPixelSamples)
      args.fail("more than " + std::to_string(Limits::kMaxPixelSamples) + " samples per axis");
    return v < 1.0 ? 1 : static_cast<int>(std::ceil(v));  // rounded up, at least 1
  };
  result_.scene.settings.samples_x = count(xs);
  result_.scene.settings.samples_y = count(ys);
}

void Parser::req_pixel_filter(ArgReader& args) {
  const std::string name = args.string();
  const double xw = args.number();
  const double yw = args.number();
  args.done();
  if (!(xw > 0 && xw <= 64 && yw > 0 && yw <= 64)) args.fail("filter widths must be in (0, 64]");
  RenderSettings& s = result_.scene.settings;
  if (name == "box") {
    s.filter = PixelFilter::Box;
  } else if (name == "gaussian") {
    s.filter = PixelFilter::Gaussian;
  } else if (name == "triangle") {
    s.filter = PixelFilter::Triangle;
  } else if (name == "blackman-harris") {
    s.filter = PixelFilter::BlackmanHarris;
  } else {
    warn_once("filter:" + name, args.request().line,
              "PixelFilter \"" + name + "\" is not supported; using gaussian");
    s.filter = PixelFilter::Gaussian;
  }
  if (xw != yw)
    warn_once("filter-aspect", args.request().line,
              "PixelFilter: different x and y widths are averaged");
  s.filter_width = static_cast<float>(0.5 * (xw + yw));
}

void Parser::req_shading_rate(ArgReader& args) {
  const double rate = args.number();
  args.done();
  if (!(rate > 0.0 && rate <= 1e6)) args.fail("shading rate must be in (0, 1e6]");
  result_.scene.settings.shading_rate = static_cast<float>(rate);
}

void Parser::req_display(ArgReader& args) {
  const std::string name = args.string();
  args.string();  // type ("file", "framebuffer", ...)
  args.string();  // mode ("rgba", ...)
  ParamList params(args, decls_);
  // Additional displays ("+name") are secondary outputs: the first one counts.
  if (result_.display_name.empty() && !name.empty() && name[0] != '+') result_.display_name = name;
}

void Parser::req_option(ArgReader& args) {
  const std::string name = args.string();
  ParamList params(args, decls_);
  if (name == "micropoly") return micropoly_option(args, params);
  if (name == "searchpath") return searchpath_option(args, params);
  warn_once("option:" + name, args.request().line, "Option \"" + name + "\" is ignored");
}

void Parser::req_attribute(ArgReader& args) {
  const std::string name = args.string();
  ParamList params(args, decls_);
  if (name == "identifier") {
    if (params.find("name")) {
      attrs_.identifier = params.get_string("name", attrs_.identifier);
      attrs_.has_identifier = true;
    }
    return;
  }
  if (name == "micropoly") return micropoly_attribute(args, params);
  if (name == "visibility") return visibility_attribute(args, params);
  warn_once("attribute:" + name, args.request().line, "Attribute \"" + name + "\" is ignored");
}

void Parser::req_declare(ArgReader& args) {
  const std::string name = args.string();
  const std::string text = args.string();
  args.done();
  if (name.empty() || name.find_first_of(" \t\n[]") != std::string::npos)
    args.fail("invalid variable name \"" + name + "\"");
  Declaration decl;
  std::string unused;
  if (!parse_declaration(text, false, &decl, &unused))
    args.fail("malformed declaration \"" + text + "\"");
  decls_.declare(name, decl);
}

void Parser::req_read_archive(ArgReader& args) {
  const std::string name = args.string();
  ParamList params(args, decls_);
  const int line = args.request().line;
  if (source_->depth + 1 > Limits::kMaxArchiveDepth)
    args.fail("archives nested deeper than " + std::to_string(Limits::kMaxArchiveDepth) +
              " (recursive ReadArchive?)");
  if (++archives_read_ > Limits::kMaxArchives)
    args.fail("more than " + std::to_string(Limits::kMaxArchives) + " archives read");
  // Relative archive paths are looked up in the archive search path, by
  // default the including file's folder. Messages name the file as found in
  // its folder; the canonical path is what is opened.
  const FoundFile file = find_file(name, false, line, "ReadArchive");
  const std::string& path = file.shown;
  std::string text, error;
  if (!read_text_file(file.open, Limits::kMaxFileBytes, &text, &error))
    fail(line, "ReadArchive: cannot read \"" + path + "\": " + error);
  parse(text, path, directory_of(path), source_->depth + 1);
}

// Option "searchpath" "string archive" "..." / "string texture" "...":
// RenderMan's search paths (':'-separated, '@' the default, '&' the previous
// value), with relative folders taken from the file holding the option.
// Only the two kinds of files a scene reads here have one; others are noted.
void Parser::searchpath_option(ArgReader& args, const ParamList& params) {
  for (const Param& p : params.params()) {
    SearchPath* target = p.name == "archive" ? &archive_search_ : p.name == "texture" ? &texture_search_ : nullptr;
    if (!target) {
      warn_once("searchpath:" + p.name, p.line, "Option \"searchpath\": \"" + p.name + "\" is ignored");
      continue;
    }
    if (!p.decl.is_string() || p.value->strings.size() != 1)
      args.fail_at(p.line, "Option \"searchpath\": \"" + p.name + "\" must be one string");
    *target = parse_search_path(p.value->strings[0], *target, *source_->base_dir);
  }
}

FoundFile Parser::find_file(const std::string& name, bool texture, int line, const std::string& request) const {
  return paths_.find(name, texture ? texture_search_ : archive_search_, *source_->base_dir, where(line), request);
}

namespace {

// Material programs are numbered by first use, materials in order and then
// the world, and those nothing uses (a material redefined without its
// program) are dropped: the Scene then holds what renders, in an order that
// does not depend on where in the file each program appeared, so a written
// scene reads back the same.
void number_programs_by_use(Scene& scene) {
  std::vector<int> renumbered(scene.material_programs.size(), -1);
  std::vector<MaterialProgram> kept;
  auto use = [&](int& program) {
    if (program < 0 || size_t(program) >= renumbered.size()) return;
    int& to = renumbered[size_t(program)];
    if (to < 0) {
      to = int(kept.size());
      kept.push_back(std::move(scene.material_programs[size_t(program)]));
    }
    program = to;
  };
  for (Material& m : scene.materials) use(m.program);
  use(scene.world.program);
  scene.material_programs = std::move(kept);
}

}  // namespace

RibResult Parser::finish(const std::string& file) {
  const Source top{&file, &file, 0};
  source_ = &top;
  if (!blocks_.empty()) {
    const Block& b = blocks_.back();
    throw RibError(b.file + ":" + std::to_string(b.line) + ": " + block_name(b.kind) +
                   " is not closed before the end of the file");
  }
  if (motion_depth_ > 0) fail(0, "MotionBegin is not closed before the end of the file");
  // Motion blocks that moved nothing the Scene keeps (a transform that no
  // shape followed, or one inside an object definition) leave a still
  // scene: the steps are dropped, so a scene renders, and writes and reads
  // back, the same either way.
  Scene& scene = result_.scene;
  const bool moves = !scene.camera.motion_world_to_camera.empty() ||
                     std::any_of(scene.meshes.begin(), scene.meshes.end(), [](const Mesh& m) {
                       return !m.motion_points.empty() || !m.motion_object_to_world.empty();
                     }) ||
                     std::any_of(scene.instances.begin(), scene.instances.end(),
                                 [](const Instance& i) { return !i.motion_object_to_world.empty(); });
  if (!moves) scene.motion_steps = 0;
  number_programs_by_use(scene);
  bool partial = false;
  for (const LightRecord& rec : lights_) {
    if (!rec.supported || !rec.on_some) continue;
    result_.scene.lights.push_back(rec.light);
    if (rec.off_some && !partial) {
      partial = true;
      result_.warnings.push_back(rec.where +
                                 ": a light illuminates only some primitives; Micropoly's lights "
                                 "are global, so it lights all of them");
    }
  }
  if (!world_done_) result_.warnings.push_back(file + ": no WorldBegin/WorldEnd: the scene is empty");
  source_ = nullptr;
  return std::move(result_);
}

}  // namespace mp::rib
