#include "scene_decoder.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace mp::fuzz {
namespace {

constexpr size_t kMaxPoints = 96;
constexpr size_t kMaxFaces = 64;
constexpr size_t kMaxItems = 4;  // materials, lights, meshes, images, ...

class Decoder {
 public:
  explicit Decoder(FuzzedDataProvider& in) : in_(in) {}

  // Mostly ordinary values, sometimes the ones validation exists for.
  float real(float lo = -4.0f, float hi = 4.0f) {
    switch (in_.ConsumeIntegralInRange<int>(0, 15)) {
      case 0: return std::numeric_limits<float>::quiet_NaN();
      case 1: return std::numeric_limits<float>::infinity();
      case 2: return -std::numeric_limits<float>::infinity();
      case 3: return in_.ConsumeBool() ? 3.0e38f : -3.0e38f;
      case 4: return std::numeric_limits<float>::denorm_min();
      case 5: return 0.0f;
      case 6: return -0.0f;
      case 7: return in_.ConsumeFloatingPoint<float>();
      case 8: return static_cast<float>(in_.ConsumeIntegralInRange<int>(-1000000, 1000000));
      default: return in_.ConsumeFloatingPointInRange<float>(lo, hi);
    }
  }
  glm::vec2 vec2() { return {real(), real()}; }
  glm::vec3 vec3() { return {real(), real(), real()}; }
  glm::vec4 vec4() { return {real(), real(), real(), real()}; }
  glm::vec3 colour() { return {real(0, 1), real(0, 1), real(0, 1)}; }
  glm::mat4 matrix() {
    glm::mat4 m(1.0f);
    switch (in_.ConsumeIntegralInRange<int>(0, 3)) {
      case 0: return m;  // identity: most objects
      case 1:             // a translation and scale
        m[3] = glm::vec4(vec3(), 1.0f);
        m[0][0] = real(), m[1][1] = real(), m[2][2] = real();
        return m;
      default:
        for (int c = 0; c < 4; ++c) m[c] = vec4();
        return m;
    }
  }
  // Counts and indices: near the valid range, sometimes far outside it.
  int integer(int lo, int hi) {
    switch (in_.ConsumeIntegralInRange<int>(0, 9)) {
      case 0: return std::numeric_limits<int>::min();
      case 1: return std::numeric_limits<int>::max();
      case 2: return in_.ConsumeIntegral<int>();
      case 3: return lo - 1;
      case 4: return hi + 1;
      default: return in_.ConsumeIntegralInRange<int>(lo, hi);
    }
  }
  int index(size_t n) { return integer(0, n > 0 ? int(n) - 1 : 0); }
  size_t count(size_t max) { return in_.ConsumeIntegralInRange<size_t>(0, max); }
  bool flag() { return in_.ConsumeBool(); }
  std::string name() { return in_.ConsumeRandomLengthString(12); }
  template <typename E>
  E enumerator(E last) { return static_cast<E>(in_.ConsumeIntegralInRange<int>(0, static_cast<int>(last))); }

  template <typename F>
  auto list(size_t max, F make) {
    std::vector<decltype(make())> v(count(max));
    for (auto& x : v) x = make();
    return v;
  }
  // An array meant to have `n` entries, but now and then one more or fewer.
  template <typename F>
  auto sized(size_t n, F make) {
    size_t len = n;
    switch (in_.ConsumeIntegralInRange<int>(0, 7)) {
      case 0: len = n + 1; break;
      case 1: len = n > 0 ? n - 1 : 0; break;
      case 2: len = count(8); break;
      default: break;
    }
    std::vector<decltype(make())> v(len);
    for (auto& x : v) x = make();
    return v;
  }

  RenderSettings settings() {
    RenderSettings s;
    if (flag()) return s;
    s.width = integer(1, 64), s.height = integer(1, 64);
    s.pixel_aspect = real(0.5f, 2.0f);
    s.crop_x0 = real(0, 1), s.crop_x1 = real(0, 1), s.crop_y0 = real(0, 1), s.crop_y1 = real(0, 1);
    s.samples_x = integer(1, 8), s.samples_y = integer(1, 8);
    s.shading_rate = real(0.25f, 4.0f);
    s.filter = enumerator(PixelFilter::BlackmanHarris);
    s.filter_width = real(0.5f, 4.0f);
    s.bound_split = enumerator(BoundSplitMethod::Breadth);
    s.bound_split_memory_mib = real(1, 64);
    s.max_grid_size = integer(1, 32), s.max_split_depth = integer(0, 32);
    s.shadow_memory_mib = real(1, 256), s.shadow_shading_rate = real(0.5f, 8.0f);
    s.world_probes = integer(0, 32);
    s.dof_dice_factor = real(0, 1);
    s.sampler = enumerator(Sampler::Bins);
    s.sample_memory_mib = real(1, 2048);
    s.backface_culling = flag(), s.shadows = flag(), s.holdout_covers = flag();
    return s;
  }

  Camera camera(int motion_steps) {
    Camera c;
    c.projection = enumerator(Camera::Projection::Orthographic);
    c.world_to_camera = matrix();
    c.fov_degrees = real(1, 179);
    if (flag()) c.screen_left = real(), c.screen_right = real(), c.screen_bottom = real(), c.screen_top = real();
    c.clip_near = real(0, 1), c.clip_far = real(1, 1000);
    if (flag()) {
      c.lens_radius = real(0, 1), c.focus_distance = real(0, 100);
      c.aperture_blades = integer(0, 8), c.aperture_rotation = real(), c.aperture_ratio = real(0.1f, 4.0f);
    }
    if (motion_steps > 0 && flag()) c.motion_world_to_camera = sized(size_t(motion_steps), [&] { return matrix(); });
    return c;
  }

  Material material(size_t programs) {
    Material m;
    m.name = name();
    m.model = enumerator(Material::Model::Principled);
    m.color = colour(), m.opacity = colour(), m.emission = colour();
    m.ka = real(0, 1), m.kd = real(0, 1), m.ks = real(0, 1), m.roughness = real(0, 1);
    m.specular_color = colour(), m.metallic = real(0, 1), m.specular = real(0, 1);
    m.layered = flag(), m.retro_diffuse = flag(), m.multiscatter = flag();
    if (flag()) {
      m.program = index(programs);
      m.program_displaces = flag(), m.program_shades = flag(), m.program_alpha = flag();
      m.program_alpha_cut = m.program_alpha && flag();
      m.displacement_bound = real(0, 1), m.displacement_bound_world = flag();
    }
    return m;
  }

  Image image() {
    Image im;
    im.name = name();
    im.width = integer(1, 8), im.height = integer(1, 8);
    const size_t n = im.width > 0 && im.height > 0 && im.width <= 8 && im.height <= 8 ? size_t(im.width) * size_t(im.height) : 4;
    im.pixels = sized(n, [&] { return vec4(); });
    im.srgb = flag();
    return im;
  }

  Light light() {
    Light l;
    l.type = enumerator(Light::Type::Environment);
    l.color = colour(), l.intensity = real(0, 10), l.position = vec3(), l.direction = vec3();
    l.cone_angle = real(0, 3.2f), l.cone_delta_angle = real(0, 1), l.beam_distribution = real(0, 4);
    l.shape = enumerator(Light::Shape::Ellipse);
    l.axis_u = vec3(), l.size_u = real(0, 4), l.size_v = real(0, 4);
    l.cast_shadows = flag(), l.radius = real(0, 1), l.soft_falloff = flag(), l.angle = real(0, 3.2f);
    l.world_probe = flag();
    if (flag()) l.irradiance_sh = sized(27, [&] { return real(); });
    return l;
  }

  World world(size_t programs) {
    World w;
    if (flag()) return w;
    w.program = flag() ? index(programs) : -1;
    w.bake_width = integer(2, 64);
    if (flag()) {
      w.width = integer(1, 8), w.height = integer(1, 8);
      const size_t n = w.width > 0 && w.height > 0 && w.width <= 8 && w.height <= 8 ? 4 * size_t(w.width) * size_t(w.height) : 4;
      w.radiance = sized(n, [&] { return real(0, 4); });
    }
    w.camera = flag(), w.diffuse = real(0, 1), w.glossy = real(0, 1), w.cast_shadows = flag();
    return w;
  }

  Mesh mesh(size_t materials, int motion_steps) {
    Mesh m;
    m.name = name();
    m.scheme = enumerator(SubdivScheme::CatmullClark);
    m.points = list(kMaxPoints, [&] { return vec3(); });
    const size_t faces = count(kMaxFaces);
    for (size_t f = 0; f < faces; ++f) {
      const int n = in_.ConsumeIntegralInRange<int>(0, 9) == 0 ? integer(0, 8) : in_.ConsumeIntegralInRange<int>(3, 6);
      m.face_vertex_counts.push_back(n);
      for (int k = 0; k < n && k < 16; ++k) m.face_vertex_indices.push_back(index(m.points.size()));
    }
    if (flag()) {  // a few indices more or fewer than the counts ask for
      if (flag()) m.face_vertex_indices.push_back(index(m.points.size()));
      else if (!m.face_vertex_indices.empty()) m.face_vertex_indices.pop_back();
    }
    const size_t corners = m.face_vertex_indices.size();
    if (m.scheme == SubdivScheme::CatmullClark) {
      const size_t creases = count(6);
      for (size_t k = 0; k < 2 * creases; ++k) m.crease_vertices.push_back(index(m.points.size()));
      m.crease_sharpness = sized(creases, [&] { return real(0, 12); });
      m.corner_vertices = list(4, [&] { return index(m.points.size()); });
      m.corner_sharpness = sized(m.corner_vertices.size(), [&] { return real(0, 12); });
      m.hole_faces = list(3, [&] { return index(faces); });
      m.boundary = enumerator(BoundaryInterpolation::EdgeAndCorner);
    }
    m.material = index(materials);
    if (flag()) m.face_materials = sized(faces, [&] { return index(materials); });
    m.object_to_world = matrix();
    m.double_sided = flag();
    if (flag()) m.texspace_location = vec3(), m.texspace_size = vec3();
    const size_t layers = count(2);
    for (size_t k = 0; k < layers; ++k) m.uv_layers.push_back(sized(corners, [&] { return vec2(); }));
    if (flag()) m.corner_normals = sized(corners, [&] { return vec3(); });
    m.visible_camera = flag(), m.cast_shadows = flag();
    m.info.color = vec4(), m.info.pass_index = real(), m.info.random = real(0, 1);
    if (motion_steps > 0 && flag()) {
      const size_t steps = size_t(motion_steps);
      m.motion_points = sized(steps, [&] { return sized(m.points.size(), [&] { return vec3(); }); });
    }
    if (motion_steps > 0 && flag()) m.motion_object_to_world = sized(size_t(motion_steps), [&] { return matrix(); });
    return m;
  }

  BezierPatches patches(size_t materials) {
    BezierPatches b;
    b.name = name();
    b.control_points = sized(16 * count(3), [&] { return vec3(); });
    b.material = index(materials);
    b.object_to_world = matrix();
    b.double_sided = flag(), b.visible_camera = flag(), b.cast_shadows = flag();
    b.info.color = vec4();
    return b;
  }

  Scene scene() {
    Scene s;
    s.motion_steps = flag() ? 0 : integer(2, 4);
    if (flag()) s.shutter_curve = list(8, [&] { return real(0, 1); });
    s.settings = settings();
    s.camera = camera(s.motion_steps > 0 && s.motion_steps <= 8 ? s.motion_steps : 0);
    const size_t programs = count(2);
    for (size_t i = 0; i < programs; ++i) s.material_programs.push_back({name(), name()});
    const size_t materials = count(kMaxItems);
    for (size_t i = 0; i < materials; ++i) s.materials.push_back(material(programs));
    s.images = list(2, [&] { return image(); });
    s.lights = list(kMaxItems, [&] { return light(); });
    s.world = world(programs);
    const int steps = s.motion_steps > 0 && s.motion_steps <= 8 ? s.motion_steps : 0;
    s.meshes = list(kMaxItems, [&] { return mesh(materials, steps); });
    s.bezier_patches = list(2, [&] { return patches(materials); });
    return s;
  }

 private:
  FuzzedDataProvider& in_;
};

}  // namespace

Scene decode_scene(FuzzedDataProvider& in) { return Decoder(in).scene(); }

}  // namespace mp::fuzz
