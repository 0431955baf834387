// The Scene: the only thing the front ends (Blender addon, RIB reader) produce
// and the only thing the pipeline consumes. It is validated once, by
// validate_scene(), so the pipeline never sees NaNs or bad indices.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace mp {

enum class SubdivScheme { None, CatmullClark };  // None: flat polygons
enum class BoundaryInterpolation { None, EdgeOnly, EdgeAndCorner };

// What Blender's Object Info node reads of an object: its Object Color
// (RGBA), Pass Index and random number (Cycles': a hash of the object's
// name, or the instance's random id, over 0xFFFFFFFF); and what Attribute
// nodes of type Object or Instancer read (an object's custom properties,
// Geometry Nodes' instance attributes): one RGBA per slot the scene's
// material programs number (the add-on's export_attributes.py), slots
// past the end reading zero.
struct ObjectInfo {
  glm::vec4 color{1.0f};
  float pass_index = 0.0f;
  float random = 0.0f;
  std::vector<glm::vec4> attributes;
  bool operator==(const ObjectInfo& o) const {
    return color == o.color && pass_index == o.pass_index && random == o.random && attributes == o.attributes;
  }
};

// A polygon or Catmull-Clark mesh. Faces may have any number (>= 3) of vertices.
struct Mesh {
  std::string name;
  SubdivScheme scheme = SubdivScheme::None;
  std::vector<glm::vec3> points;             // object space
  std::vector<int> face_vertex_counts;       // one entry per face
  std::vector<int> face_vertex_indices;      // concatenated, counter-clockwise = front
  // Catmull-Clark tags (ignored for polygon meshes).
  std::vector<int> crease_vertices;          // pairs of vertex indices, one pair per creased edge
  std::vector<float> crease_sharpness;       // one per creased edge; >= 10 is infinitely sharp
  std::vector<int> corner_vertices;
  std::vector<float> corner_sharpness;       // one per corner vertex
  std::vector<int> hole_faces;               // faces that are not rendered
  BoundaryInterpolation boundary = BoundaryInterpolation::EdgeAndCorner;
  // Materials: face_materials (one per face) if not empty, else `material`.
  int material = 0;
  std::vector<int> face_materials;
  glm::mat4 object_to_world{1.0f};
  bool double_sided = true;
  // Texture space for Generated coordinates: (P - location) / (2 size) + 1/2.
  // A zero size means the bounding box of `points`.
  glm::vec3 texspace_location{0.0f};
  glm::vec3 texspace_size{0.0f};
  // UV maps, each one (u, v) per face corner (face_vertex_indices order).
  // Layer k is what material programs read as UV layer k (MpNodeGlobals.uv);
  // a mesh with fewer layers reads zeros from the missing ones. Inside each
  // face (each ptex sub-face of a subdivided non-quad) UVs interpolate
  // bilinearly, as OpenSubdiv's face-varying "linear all" rule does.
  std::vector<std::vector<glm::vec2>> uv_layers;
  // Shading normals per face corner (object space), for polygon meshes that
  // are shaded smooth: interpolated across each face (bilinearly, like UVs).
  // Empty: flat faces. Ignored for Catmull-Clark meshes (their limit surface
  // is smooth by itself).
  std::vector<glm::vec3> corner_normals;
  // Ray visibility (Blender's Object > Visibility): seen by the camera, and
  // casting shadows (in the lights' shadow maps).
  bool visible_camera = true;
  bool cast_shadows = true;
  ObjectInfo info;
  // Motion blur (Scene::motion_steps): the points (deformation) and the
  // transform at each motion step, or empty where they do not move; the
  // fields above are the shutter centre's.
  std::vector<std::vector<glm::vec3>> motion_points;
  std::vector<glm::mat4> motion_object_to_world;
};

// Bicubic patches already converted to Bezier form: 16 control points per
// patch, row-major with u varying fastest (cp[4*j + i]).
struct BezierPatches {
  std::string name;
  std::vector<glm::vec3> control_points;
  int material = 0;
  glm::mat4 object_to_world{1.0f};
  bool double_sided = true;
  bool visible_camera = true;  // as Mesh
  bool cast_shadows = true;
  ObjectInfo info;
  // u runs around a round section (hair tubes): the camera dices at least a
  // few micropolygons across u, whatever the size on screen (MP_PATCH_ROUND_U).
  bool round_u = false;
  // Each patch is a strand segment drawn as a ribbon facing each view
  // (MP_PATCH_CURVE; its 16 points laid out as kernels/geometry/mp_patch.h
  // says: per row j the centre point and the three radius points).
  bool ribbons = false;
  // What material programs read as UV layer k (as Mesh::uv_layers): 4 values
  // per patch, at its corners (0,0), (1,0), (1,1), (0,1), interpolated
  // bilinearly across it. Hair tubes carry their curves' UVs, attributes and
  // Hair Info values here (scene/curves.h). Empty: zeros.
  std::vector<std::vector<glm::vec2>> uv_layers;
  // Motion blur (Scene::motion_steps): the control points and the transform
  // at each motion step, or empty where they do not move (as Mesh).
  std::vector<std::vector<glm::vec3>> motion_control_points;
  std::vector<glm::mat4> motion_object_to_world;
};

// Instancing (RenderMan's ObjectBegin/ObjectInstance; Blender's instances):
// a prototype is a set of surfaces, each placed in the prototype's own space
// by its object_to_world, rendered only where instances place it. Its
// patches are built once however many instances place it.
struct Prototype {
  std::string name;
  std::vector<Mesh> meshes;
  std::vector<BezierPatches> bezier_patches;
};

// One placement of a prototype. Its surfaces keep their geometry, UVs,
// materials per face and texture space; the instance brings where they are
// (object_to_world: prototype space -> world, composed with each surface's
// own), what Object Info reads (info), and the RIB attributes current at
// ObjectInstance: a material that replaces each surface's `material`
// (-1: their own; face_materials still apply), sidedness (-1: their own,
// 0 one-sided, 1 double-sided), ray visibility (combined with the surfaces'
// own: a surface is seen where both say so) and RenderMan's
// ReverseOrientation (front and back swapped).
struct Instance {
  std::string name;  // for messages; made real, its copies' names
  int prototype = 0;
  glm::mat4 object_to_world{1.0f};
  ObjectInfo info;
  int material = -1;
  int double_sided = -1;
  bool visible_camera = true;
  bool cast_shadows = true;
  bool reverse_orientation = false;
  // Motion blur (Scene::motion_steps): the transform at each step, or empty
  // where it does not move. Prototypes' meshes do not deform over the
  // shutter (their motion_points stay empty): their instances move whole.
  std::vector<glm::mat4> motion_object_to_world;
};

// Materials. Constant, Matte and Plastic follow RenderMan's shaders (Cs,
// Ka, Kd, Ks, roughness, specularcolor; no 1/pi in the diffuse term).
// Principled follows Blender's Principled BSDF in physical units: a
// Lambertian lobe of albedo color * (1 - metallic) (1/pi included) and a GGX
// lobe with Schlick Fresnel, F0 = 0.08 * specular for dielectrics, tinted by
// color for metals, alpha = roughness^2. Emission is added as is (radiance).
struct Material {
  enum class Model { Constant, Matte, Plastic, Principled };
  std::string name;
  Model model = Model::Plastic;
  glm::vec3 color{1.0f};
  glm::vec3 opacity{1.0f};
  float ka = 1.0f, kd = 0.5f, ks = 0.5f, roughness = 0.1f;
  glm::vec3 specular_color{1.0f};
  float metallic = 0.0f;   // Principled only
  float specular = 0.5f;   // Principled only
  // Principled only: Blender 4.0's layered Principled BSDF, whose diffuse
  // base lies under the specular layer and gets the light it lets through.
  bool layered = false;
  // Principled only: the diffuse lobe is Disney's with retro-reflection
  // (Blender 3.x's Principled BSDF) rather than Lambert (a Diffuse BSDF, or
  // 4.x), and the glossy lobes compensate multiple scattering (Multiscatter GGX).
  bool retro_diffuse = false;
  bool multiscatter = false;
  glm::vec3 emission{0.0f};
  // A node tree compiled to a material program (Scene::material_programs),
  // or -1. The program may displace the surface (displacement_bound is then
  // how far, in object-space units, it can move it) and/or compute the
  // Principled inputs above per shading point.
  int program = -1;
  bool program_displaces = false;
  bool program_shades = false;
  // The program computes the alpha (opacity), which the shadow views then
  // evaluate too, so that a texture's cut-outs cast cut-out shadows.
  bool program_alpha = false;
  // ... a hard cut whose per-point value is its edge's distance (a Math
  // Greater or Less Than into Alpha: mp_alpha_cut in mp_node_lib.h):
  // samples and shadow texels keep the surface where it exceeds one half.
  bool program_alpha_cut = false;
  // The program's node values (the numbers it reads rather than compiles
  // in: node_compiler.py), so that materials whose trees differ only in
  // values share one program, and editing a value rebuilds nothing.
  std::vector<float> program_params;
  float displacement_bound = 0.0f;
  // The bound is in world units rather than object units (a Displacement
  // node in World space: its distance does not scale with the object).
  bool displacement_bound_world = false;
};

// A material node tree translated to OpenCL C: `source` defines
// mp_node_displacement and mp_node_surface (the contract is in
// kernels/materials/material_program.cl and mp_node_lib.h). Materials with
// identical trees share one program, built once.
struct MaterialProgram {
  std::string name;    // for messages: the material it came from
  std::string source;
};

// A texture image for material programs (Image Texture nodes): RGBA, rows
// bottom to top as Blender stores them; texel (i, j) covers [i, i+1]/width x
// [j, j+1]/height of UV space. Pixels are scene-linear, or, with `srgb`,
// sRGB-encoded values that are decoded after filtering, as Cycles treats
// 8-bit sRGB images (so filtered results match it).
struct Image {
  std::string name;
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;  // width * height
  bool srgb = false;
};

// Light sources in world space. For point and spot lights color * intensity
// is the radiant intensity (the 1/d^2 falloff is applied); for distant lights
// the irradiance on a surface facing them; for ambient lights the incoming
// radiance from every direction; for area lights the radiance leaving the
// emitting side (the side `direction` points to). The spot cone blends
// smoothly from cone_angle - cone_delta_angle to cone_angle (half-angles,
// radians) and is raised to beam_distribution, as RenderMan's spotlight.
// Area lights are rectangles or ellipses centred on `position`, with
// `size_u` along `axis_u` and `size_v` along direction x axis_u.
// Shadows (every type but ambient, with cast_shadows): shadow maps made by
// the pipeline itself (kernels/shadow/mp_shadow.h), soft by the light's size:
// `radius` for point and spot lights, `angle` (the angular diameter) for
// distant lights, the area for area lights. A point or spot light with a
// radius is a disk of that radius facing the lit point, as Cycles' point
// light with soft falloff; without soft_falloff (Blender 4.1 and later) a
// sphere, which lights as the point does while it is above the horizon.
struct Light {
  // Environment: the world's light (World below), made by the renderer.
  enum class Type { Ambient, Distant, Point, Spot, Area, Environment };
  enum class Shape { Rectangle, Ellipse };
  Type type = Type::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // direction the light travels
  float cone_angle = 0.5235988f;           // 30 degrees
  float cone_delta_angle = 0.0872665f;     // 5 degrees
  float beam_distribution = 2.0f;
  Shape shape = Shape::Rectangle;          // area lights
  glm::vec3 axis_u{1.0f, 0.0f, 0.0f};
  float size_u = 1.0f, size_v = 1.0f;
  bool cast_shadows = true;
  float radius = 0.0f;                     // point and spot lights
  bool soft_falloff = true;
  float angle = 0.0f;                      // distant lights, radians
  // Lights the renderer derives from the world (world_lighting.h): a
  // distant probe gives no light of its own, only its shadow map's
  // visibility; the environment light holds the world's irradiance as
  // spherical harmonics (9 RGB coefficients, world space, already scaled
  // by the cosine lobe's A_l / pi) and the world's diffuse and glossy
  // visibility factors in color.
  bool world_probe = false;
  std::vector<float> irradiance_sh;
};

// The world: light from every direction and what the camera sees behind
// objects. Its radiance is an equirectangular map in world space (Blender's
// and Cycles' convention: +Z up; a direction d sits at u = 0.5 -
// atan2(d.y, d.x) / 2pi, v = 0.5 + asin(d.z) / pi, rows from the bottom),
// either given (`radiance`, RGBA) or baked on the device from a world
// program, a node tree the add-on compiled like a material's (its Surface
// emission is the radiance). Without either, the scene has no world light.
struct World {
  int program = -1;                 // index into Scene::material_programs
  std::vector<float> program_params;  // its node values (Material::program_params)
  int bake_width = 512;             // the baked map's width; its height is half
  int width = 0, height = 0;        // of `radiance`
  std::vector<float> radiance;
  bool camera = true;               // seen behind objects on an opaque film
  float diffuse = 1.0f, glossy = 1.0f;  // Ray Visibility: light on diffuse and glossy lobes
  bool cast_shadows = true;         // the scene shadows its world light
  bool present() const { return program >= 0 || (width > 0 && height > 0); }
};

// Camera: right-handed camera space, looking down -Z with +Y up (Blender's
// convention; the RIB reader converts from RenderMan's left-handed space).
// Perspective screen coordinates are (x, y) / (-z * tan(fov/2)); orthographic
// ones are (x, y). The screen window maps onto the image; left == right means
// "derive it from the aspect ratio" (RenderMan's default: the shorter image
// side spans [-1, 1]).
struct Camera {
  enum class Projection { Perspective, Orthographic };
  Projection projection = Projection::Perspective;
  glm::mat4 world_to_camera{1.0f};
  float fov_degrees = 90.0f;
  float screen_left = 0, screen_right = 0, screen_bottom = 0, screen_top = 0;
  float clip_near = 0.01f;
  float clip_far = 1.0e30f;
  // Depth of field (a thin lens; perspective cameras): the aperture's radius
  // in scene units (0: a pinhole), the distance in focus along the view
  // axis, the aperture's polygon (blades < 3: round) and its rotation in
  // radians, and the anamorphic ratio (the aperture's x is radius / ratio),
  // as Cycles defines them.
  float lens_radius = 0.0f;
  float focus_distance = 10.0f;
  int aperture_blades = 0;  // at most kMaxApertureBlades
  static constexpr int kMaxApertureBlades = 1000;
  float aperture_rotation = 0.0f;
  float aperture_ratio = 1.0f;
  // Motion blur (Scene::motion_steps): the camera at each step, or empty.
  std::vector<glm::mat4> motion_world_to_camera;
};

enum class PixelFilter { Box, Gaussian, Triangle, BlackmanHarris };
enum class BoundSplitMethod { Bounded, Breadth };
// The sample stage: screen tiles, one work-item owning each tile's samples
// (kernels/stages/sample_tiles.cl, made for CPUs); one work-item per
// micropolygon with atomics on the frame's samples (kernels/stages/sample.cl);
// or bins of pixels, a work-group per bin holding its samples' depths in
// local memory (kernels/stages/sample_bins.cl; blurred frames, and sample
// counts whose bin does not fit local memory, take sample.cl). All give the
// same image; Auto takes tiles on CPUs and micropolygons on GPUs (where the
// bins measured slower: docs/performance.md).
enum class Sampler { Auto, Tiles, Micropolygons, Bins };
// The resolve (kernels/stages/resolve.cl): tiles of pixels that first load
// their samples and the filter's reach around them into local memory (made
// for GPUs: each sample is read from device memory once a tile, not once
// for every pixel its filter reaches), or one work-item per pixel reading
// its neighbours' samples itself (made for CPUs, vectorised over samples).
// Both give the same image to float rounding; Auto picks by the device's
// type.
enum class Resolver { Auto, Tiles, Pixels };
// Visibility first (docs/pipeline.md, step 5): each batch of the camera's
// view finds the depth of its opaque grids before shading and shades only
// those that own a sample; the image is the same either way. It costs a
// depth pass and a marking pass per batch and saves the shading of hidden
// grids: Auto takes it where the view's roots overlap enough to hide much
// (CameraView's rule), On and Off always and never.
enum class VisibilityFirst { Auto, On, Off };
// Whether the camera's view takes its roots in waves with occlusion culling
// (pipeline/pass/bound_split_bounded.cpp, docs/pipeline.md step 3): the
// nearest first, sampled before the next are split, so the pyramid hides
// what lies behind them early. Each wave costs a partly filled dice batch,
// which on a GPU is launches and host waits: Auto takes waves on CPU
// devices, and on GPUs where the roots' boxes overlap deeply (camera_view.cpp).
// The image is the same either way.
enum class OcclusionWaves { Auto, On, Off };
// How the image comes back to the host: its colour as floats; its colour
// rounded to half floats on the device, half the bytes to carry (what the
// viewport asks: it draws half-float textures; the result still holds
// floats, each the nearest half to the float image's); or not at all, for
// benchmarks of the frame without its read-back (the result holds no
// pixels). Depth and Normal always come back as floats.
enum class ReadBack { Float, Half, None };

struct RenderSettings {
  int width = 640, height = 480;
  float pixel_aspect = 1.0f;
  // Crop (border) window in normalized [0,1] image coordinates, y down.
  float crop_x0 = 0, crop_x1 = 1, crop_y0 = 0, crop_y1 = 1;
  int samples_x = 4, samples_y = 4;            // stratified samples per pixel
  float shading_rate = 1.0f;                   // micropolygon area in pixels
  PixelFilter filter = PixelFilter::Gaussian;
  float filter_width = 2.0f;                   // total width in pixels
  BoundSplitMethod bound_split = BoundSplitMethod::Bounded;
  float bound_split_memory_mib = 64.0f;        // budget of the bounded method
  // The bounded method's launches chained on the device between two host
  // reads of its counters (at most this many); the image is the same for
  // any value. 1 (no chains): on the H100 a launch costs the host nearly
  // what a read does, and chains did not pay (docs/performance.md).
  int bound_split_chain = 1;
  // The sub-patches each worker of the bounded method handles per launch
  // before the host reads the counters; the image is the same for any
  // value. 0 (auto): 1 on GPUs, whose launches last as long as their
  // busiest worker's steps, so short launches let handed-out work reach idle
  // workers sooner (about half the bound & split time of 16 on the H200);
  // 16 on CPUs, where a launch and its read cost more than a step
  // (docs/performance.md, "Bound & split in short launches on GPUs").
  int bound_split_steps = 0;
  int max_grid_size = 16;                      // micropolygons per grid side
  int max_split_depth = 26;                    // eye-split and runaway limit
  bool backface_culling = true;                // for single-sided surfaces
  bool depth_and_normal_passes = true;         // resolve and return Depth and Normal
  bool normal_pass = true;                     // with them, samples keep normals (Depth needs none)
  ReadBack read_back = ReadBack::Float;
  // Shadow maps (kernels/shadow/mp_shadow.h): on for lights that cast shadows; the
  // device memory their pages, page tables and requests may take; the area
  // of a shadow view's micropolygons in texels of its map.
  bool shadows = true;
  float shadow_memory_mib = 256.0f;
  float shadow_shading_rate = 4.0f;
  // A renderer keeps shadow pages whose light and geometry did not change
  // for its next frames (the viewport's redraws); off, every frame renders
  // its shadow maps anew (benchmarks).
  bool keep_shadow_pages = true;
  // Soft shadows' finer pages, where their first search finds occluders (a
  // second marking and pass); off, penumbrae read the levels the first
  // marking made, coarser near contact (the viewport's preview pass).
  bool soft_shadow_pages = true;
  // Bound & split drops sub-patches hidden behind what earlier dice batches
  // sampled (kernels/stages/mp_occlusion.h); the image is the same either way.
  bool occlusion_culling = true;
  // Bound & split drops bounds of a pixel or two that hold none of the
  // view's samples (mp_bound.h, mp_bound_misses_samples), so distant
  // instances cost the samples they cover, not their patches; the image is
  // the same either way.
  bool sample_culling = true;
  // The world's light is shadowed through this many probe directions
  // (world_lighting.h), each a soft-shadowed distant light.
  int world_probes = 16;
  // Out of focus, a sub-patch's target micropolygon edge grows to this
  // fraction of its circle of confusion's diameter where that is longer
  // (RenderMan's focus factor): blurred surfaces are diced coarser. 0: off.
  float dof_dice_factor = 0.5f;
  // Image textures are filtered over this many times each micropolygon's
  // footprint in the texture (kernels/textures/mp_tex_image.h; RenderMan's
  // filter width); 0 reads the point each vertex lands on, unfiltered.
  float texture_filter_width = 1.0f;
  Sampler sampler = Sampler::Auto;
  Resolver resolver = Resolver::Auto;
  VisibilityFirst visibility_first = VisibilityFirst::Auto;
  OcclusionWaves occlusion_waves = OcclusionWaves::Auto;
  // Device memory the frame's samples may take (24 bytes each, 20 without
  // the Normal pass): a frame that needs more is rendered in buckets that
  // fit, each with the pixel filter's reach of samples around it.
  float sample_memory_mib = 2048.0f;
  // Held-out samples (Holdout shaders) count as covered in the alpha, so a
  // background laid behind by alpha shows nowhere through them (Blender's
  // opaque film; Cycles keeps their colour black there too). Off: they are
  // transparent, alpha 0 (Film > Transparent, and the CLI's images).
  bool holdout_covers = false;
};

struct Scene {
  Camera camera;
  RenderSettings settings;
  std::vector<Material> materials;             // index 0 is the default
  std::vector<MaterialProgram> material_programs;
  std::vector<Image> images;
  std::vector<Light> lights;
  World world;
  std::vector<Mesh> meshes;
  std::vector<BezierPatches> bezier_patches;
  std::vector<Prototype> prototypes;
  std::vector<Instance> instances;
  // Motion blur: 0 (none), or the number (2 to kMaxMotionSteps) of times,
  // evenly spread over the shutter from its opening (0) to its closing (1),
  // at which the camera, meshes and their transforms give their positions
  // (motion_* fields). Each sample takes its own time in the shutter and sees
  // the scene linearly between the steps; shading uses the transforms and
  // points of the shutter's centre (the objects' own fields).
  int motion_steps = 0;
  // How open the shutter is over its time (Render > Motion Blur > Shutter
  // Curve), sampled evenly from its opening to its closing (piecewise
  // linear between); samples' times follow it. Empty: fully open throughout.
  std::vector<float> shutter_curve;
};
constexpr int kMaxMotionSteps = 33;
constexpr size_t kMaxShutterCurve = 4096;

// Checks indices, counts and finite values; throws mp::Error naming the object.
void validate_scene(const Scene& scene);

// The scene with every instance made real: each instance's prototype
// surfaces appended to meshes and bezier_patches as objects of their own,
// placed and attributed as the instance says (named as the instance, or
// "<prototype>/<surface>#<index>" where it has no name); prototypes and
// instances emptied.
// What an instanced scene must render like.
Scene with_instances_made_real(const Scene& scene);

}  // namespace mp
