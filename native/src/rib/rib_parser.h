// The RIB interpreter: executes requests against a graphics-state stack and
// fills a Scene. Handlers are split by topic over several files:
//   rib_parser.cpp    dispatch, blocks, options and camera, archives
//   rib_transform.cpp transformations, named coordinate systems, orientation,
//                     sides and visibility
//   rib_shading.cpp   surfaces, colors, lights, materials
//   rib_geometry.cpp  polygons, subdivision meshes, patches
//   rib_objects.cpp   placing primitives in the scene, object instancing
//   rib_micropoly.cpp the "micropoly" options, attributes and parameters
//                     (Micropoly's extensions, written by rib_writer.cpp)
#pragma once

#include <map>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "rib/rib_basis.h"
#include "rib/rib_params.h"
#include "rib/rib_paths.h"
#include "rib/rib_reader.h"
#include "rib/rib_request.h"

namespace mp::rib {

// Limits that keep hostile input from exhausting memory or time.
struct Limits {
  static constexpr int kMaxArchiveDepth = 16;       // nested ReadArchive
  static constexpr int kMaxArchives = 256;          // ReadArchive calls per file
  static constexpr size_t kMaxFileBytes = size_t(1) << 30;
  static constexpr size_t kMaxBlockDepth = 1000;    // nested Begin/End blocks
  static constexpr int kMaxLights = 1024;
  static constexpr size_t kMaxSceneElements = size_t(1) << 29;  // points + indices (6 GiB of points)
  static constexpr int kMaxResolution = 65536;
  static constexpr int kMaxPixelSamples = 64;
  static constexpr size_t kMaxTexels = size_t(1) << 27;  // all texture images together
};

// Graphics-state attributes (RI spec 3.2, section 4.2). The current
// transformation is kept relative to the camera before WorldBegin and
// relative to world space inside the world block, both in GLM's
// column-vector convention (the transpose of RenderMan's row-vector matrices).
struct Attributes {
  glm::mat4 ctm{1.0f};
  // The current transformation at each motion step after a MotionBegin of
  // transformations (empty: it does not move); ctm is the shutter centre's.
  std::vector<glm::mat4> motion_ctm;
  glm::vec3 color{1.0f};
  glm::vec3 opacity{1.0f};
  Material surface;           // model and shader parameters; color/opacity apply at emission
  bool double_sided = true;   // Sides 2 is RenderMan's default
  // Attribute "micropoly" "int roundu": patches whose u runs around a round
  // section (hair tubes written back; BezierPatches::round_u).
  bool round_u = false;
  // Attribute "micropoly" "int ribbons": patches that are strand segments
  // drawn as ribbons facing each view (ribbons written back;
  // BezierPatches::ribbons).
  bool ribbons = false;
  // True when the current orientation differs from the handedness of the
  // current coordinate system, i.e. the primitives' normals are flipped. Both
  // flip together under transformations, so only Orientation and
  // ReverseOrientation change this.
  bool inside_out = false;
  // Attribute "visibility": seen by the camera ("camera"), and casting
  // shadows ("transmission", RenderMan's shadow rays).
  bool visible_camera = true;
  bool cast_shadows = true;
  std::vector<char> lights_on;  // by light index; lights past the end are off
  Basis ubasis, vbasis;
  std::string identifier;       // Attribute "identifier" "name"
  bool has_identifier = false;  // given, even if empty
  // Scene material chosen by Attribute "micropoly" "integer material"; -1:
  // none (the shading state above picks one). Surface, Color and Opacity reset it.
  int material_slot = -1;
  // Attribute "micropoly" "color objectcolor" / "float objectalpha" /
  // "float objectindex" / "float objectrandom": what Object Info reads.
  ObjectInfo object_info;
};

// A primitive before it is placed: geometry in its own object space, vertex
// order as in the file. Object definitions store these for ObjectInstance.
struct Primitive {
  enum class Kind { Mesh, Patches };
  Kind kind = Kind::Mesh;
  Mesh mesh;                             // Kind::Mesh
  std::vector<glm::vec3> patch_points;   // Kind::Patches: Bezier nets, 16 per patch
  std::vector<std::vector<glm::vec2>> patch_uvs;  // Kind::Patches: BezierPatches::uv_layers
  glm::mat4 local{1.0f};                 // relative to the object definition's frame
  bool mergeable = false;                // Polygon/Patch runs may share one scene object
  std::string origin;                    // "Request (file:line)" for naming
  size_t elements() const;
};

struct LightRecord {
  bool supported = false;
  Light light;               // position/direction in the frame below
  glm::vec3 direction{0.0f};  // "to" - "from" in the frame below, not yet normalised
  bool in_camera = false;    // declared before WorldBegin: converted at WorldBegin
  bool on_some = false;      // illuminated at least one primitive
  bool off_some = false;     // was off for at least one later primitive
  std::string where;         // "file:line" of the LightSource request
};

class Parser {
 public:
  // `scene_dir` is the top-level file's folder; `options` which other
  // folders the scene may read from (rib_paths.h).
  Parser(const std::string& scene_dir, const RibReadOptions& options);
  // Executes the requests of one file (the top level or a ReadArchive).
  void parse(std::string_view text, const std::string& file, const std::string& base_dir, int depth);
  // Checks that every block is closed and returns the scene.
  RibResult finish(const std::string& file);

 private:
  using Handler = void (Parser::*)(ArgReader&);
  struct Source {
    const std::string* file;
    const std::string* base_dir;
    int depth;
  };
  struct Block {
    enum class Kind { Frame, World, Attribute, Transform, Object, Solid };
    Kind kind;
    int line;
    std::string file;
    Attributes saved;
  };
  struct CoordSys {
    bool in_world;
    glm::mat4 ctm;
  };
  struct ObjectDef {
    std::vector<Primitive> prims;
    int prototype = -1;  // its Scene prototype, once an instance placed it
  };
  struct MergeTarget {
    Primitive::Kind kind;
    size_t index;
    glm::mat4 object_to_world;
    int material;
    bool double_sided;
    bool round_u;
    bool ribbons;
    bool visible_camera;
    bool cast_shadows;
    ObjectInfo object_info;
    std::string identifier;
    bool has_identifier;
  };

  static const std::unordered_map<std::string, Handler>& handlers();
  void execute(const Request& req);
  void warn(int line, const std::string& message);
  void warn_once(const std::string& key, int line, const std::string& message);
  [[noreturn]] void fail(int line, const std::string& reason) const;
  std::string where(int line) const;
  void charge(size_t elements, int line);
  void note_primitive(const Attributes& attrs, int line);
  void add_instance(ObjectDef& def, const std::string& key, int line);
  void push_block(Block::Kind kind, int line);
  void pop_block(Block::Kind kind, ArgReader& args);
  static const char* block_name(Block::Kind kind);
  std::string handle_key(ArgReader& args);
  bool current_frame_is_left_handed() const;
  const glm::mat4& camera_inverse(int line);

  // rib_parser.cpp: structure, options, camera
  void req_version(ArgReader&);
  void req_frame_begin(ArgReader&);
  void req_frame_end(ArgReader&);
  void req_world_begin(ArgReader&);
  void req_world_end(ArgReader&);
  void req_attribute_begin(ArgReader&);
  void req_attribute_end(ArgReader&);
  void req_transform_begin(ArgReader&);
  void req_transform_end(ArgReader&);
  void req_solid_begin(ArgReader&);
  void req_solid_end(ArgReader&);
  void req_motion_begin(ArgReader&);
  void req_shutter(ArgReader&);
  void req_motion_end(ArgReader&);
  void req_format(ArgReader&);
  void req_projection(ArgReader&);
  void req_screen_window(ArgReader&);
  void req_crop_window(ArgReader&);
  void req_clipping(ArgReader&);
  void req_depth_of_field(ArgReader&);
  void req_pixel_samples(ArgReader&);
  void req_pixel_filter(ArgReader&);
  void req_shading_rate(ArgReader&);
  void req_display(ArgReader&);
  void req_option(ArgReader&);
  void req_attribute(ArgReader&);
  void req_declare(ArgReader&);
  void req_read_archive(ArgReader&);
  // Option "searchpath": where relative archive and texture names are looked up.
  void searchpath_option(ArgReader& args, const ParamList& params);
  // The file `name` stands for, under the searchpath and the path rule
  // (PathPolicy::find); `texture` picks the texture search path over the
  // archive one.
  FoundFile find_file(const std::string& name, bool texture, int line, const std::string& request) const;
  void req_ignore(ArgReader&);

  // rib_transform.cpp
  void req_identity(ArgReader&);
  void req_transform(ArgReader&);
  void req_concat_transform(ArgReader&);
  void req_translate(ArgReader&);
  void req_rotate(ArgReader&);
  void req_scale(ArgReader&);
  void req_coordinate_system(ArgReader&);
  void req_coord_sys_transform(ArgReader&);
  void req_orientation(ArgReader&);
  void req_reverse_orientation(ArgReader&);
  void req_sides(ArgReader&);
  void visibility_attribute(ArgReader& args, const ParamList& params);
  glm::mat4 read_matrix(ArgReader& args);

  // rib_shading.cpp
  void req_color(ArgReader&);
  void req_opacity(ArgReader&);
  void req_surface(ArgReader&);
  void req_light_source(ArgReader&);
  void req_illuminate(ArgReader&);
  int material_index(const Attributes& attrs);
  static std::vector<float> material_key(const Material& m);
  void convert_camera_lights(int line);
  void finish_light(LightRecord& rec, int line);

  // rib_geometry.cpp
  void req_polygon(ArgReader&);
  void req_general_polygon(ArgReader&);
  void req_points_polygons(ArgReader&);
  void req_points_general_polygons(ArgReader&);
  void req_subdivision_mesh(ArgReader&);
  void req_patch(ArgReader&);
  void req_patch_mesh(ArgReader&);
  void req_quadric(ArgReader&);  // Sphere, Cylinder, Cone, Disk, Paraboloid, Hyperboloid, Torus
  void req_points(ArgReader&);
  void req_curves(ArgReader&);   // rib_curves.cpp
  void req_nupatch(ArgReader&);  // rib_nupatch.cpp
  void req_basis(ArgReader&);
  // Positions from "P" or "Pw"; false (with a warning) if the primitive must be skipped.
  bool read_positions(ArgReader& args, const ParamList& params, bool patch,
                      std::vector<glm::vec3>* out);
  Primitive make_primitive(Primitive::Kind kind, const ArgReader& args) const;

  // rib_objects.cpp
  void req_object_begin(ArgReader&);
  void req_object_end(ArgReader&);
  void req_object_instance(ArgReader&);
  // Places a primitive with the current state: into the open object
  // definition, or into the scene (inside the world block only).
  void place(Primitive prim, const ArgReader& args);
  void add_to_scene(const Primitive& prim, const glm::mat4& xform, const Attributes& attrs, int line);
  void account_lights(const Attributes& attrs);

  // rib_micropoly.cpp
  void micropoly_option(ArgReader& args, const ParamList& params);
  void micropoly_attribute(ArgReader& args, const ParamList& params);
  // The material program a micropoly material attribute names (Material::program).
  struct MaterialProgramUse {
    int program = -1;
    bool displaces = false, shades = false, alpha = false, alpha_cut = false;
    float displacement_bound = 0.0f;
    bool displacement_world = false;
    std::vector<float> params;  // the program's node values
  };
  void define_material(int index, const std::string& name, const MaterialProgramUse& use);
  // Per-face Scene material indices ("uniform integer micropoly:material"),
  // left empty when the parameter is absent.
  void read_face_materials(ArgReader& args, const ParamList& params, size_t faces,
                           std::vector<int>* out) const;
  // UV layers ("micropoly:uv0".."micropoly:uv7", float[2], per face corner
  // or per vertex) for the face corners `corners` (vertex indices), the
  // Generated texture space ("micropoly:texspacelocation", "...size") and,
  // for polygon meshes, shading normals ("N", per face corner or vertex).
  void read_mesh_primvars(ArgReader& args, const ParamList& params, const std::vector<int>& corners,
                           size_t npoints, Mesh* mesh) const;
  // A Patch's corner UVs ("varying float[2] micropoly:uvK": 4 per layer, u
  // fastest, as RenderMan orders a patch's varying values) into
  // prim->patch_uvs (BezierPatches::uv_layers' corner order).
  void read_patch_primvars(ArgReader& args, const ParamList& params, Primitive* prim) const;
  // Refuses a program `source` that reaches beyond the device
  // (rib_program_check.h) unless any path is allowed (the file is trusted).
  void check_program(const std::string& source, const ParamList& params, const std::string& what) const;
  // One texture image named by Option "micropoly" "string imagefile".
  void read_image_option(ArgReader& args, const ParamList& params);
  // MakeTexture: a texture name that later image options read as its picture.
  void req_make_texture(ArgReader& args);
  // The file a texture image or map named `name` reads: the picture a
  // MakeTexture made it from, else the file itself (find_file).
  std::string texture_file(const std::string& name, int line, const std::string& request) const;
  // LightSource "micropoly_environmentlight": the Scene's World (docs/rib.md).
  void read_environment_light(ArgReader& args, const ParamList& params);

  // State.
  RibResult result_;
  DeclarationTable decls_;
  Attributes attrs_;
  std::vector<Block> blocks_;
  const Source* source_ = nullptr;
  std::set<std::string> warned_;
  size_t texels_ = 0;  // read so far, against Limits::kMaxTexels
  std::map<std::string, std::string> made_textures_;  // MakeTexture: texture name -> its picture's path
  PathPolicy paths_;
  SearchPath archive_search_ = default_search_path();
  SearchPath texture_search_ = default_search_path();

  bool in_world_ = false;
  bool world_done_ = false;    // the first world block has ended
  bool skipping_ = false;      // later frames: requests are read but not executed
  int motion_depth_ = 0;       // inside MotionBegin/MotionEnd
  std::vector<double> motion_times_;     // of the open block
  std::vector<Request> motion_requests_;  // collected until MotionEnd
  int motion_line_ = 0;
  double shutter_open_ = 0.0, shutter_close_ = 0.0;
  bool shutter_set_ = false;
  void run_motion_block(int line);
  void run_handler(const Request& req);
  bool motion_usable(int line);
  glm::mat4 camera_{1.0f};     // RenderMan world-to-camera (column-vector convention)
  glm::mat4 camera_inv_{1.0f};
  bool camera_inv_valid_ = false;
  int archives_read_ = 0;
  size_t elements_ = 0;
  size_t prims_emitted_ = 0;
  bool shading_rate_used_ = false;
  float shading_rate_at_use_ = 1.0f;

  std::map<std::string, CoordSys> coord_systems_;
  std::vector<LightRecord> lights_;
  std::unordered_map<std::string, int> light_handles_;
  std::unordered_map<std::string, ObjectDef> objects_;
  std::string defining_;       // key of the object being defined, empty if none
  bool defining_active_ = false;
  ObjectDef definition_;
  std::map<std::vector<float>, int> material_keys_;
  bool has_merge_target_ = false;
  MergeTarget merge_;
};

}  // namespace mp::rib
