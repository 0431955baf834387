#include "pipeline/device_scene/scene_fingerprint.h"

#include <algorithm>
#include <cstring>
#include <type_traits>

namespace mp {
namespace {

// FNV-1a over 64-bit words (the tail byte by byte): fast enough to run over
// a million-face mesh in milliseconds. Values are hashed field by field, so
// struct padding never enters.
class Hasher {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    size_t words = n / 8;
    for (size_t i = 0; i < words; ++i) {
      uint64_t w;
      std::memcpy(&w, p + 8 * i, 8);
      mix(w);
    }
    for (size_t i = words * 8; i < n; ++i) mix(p[i]);
    mix(n);
  }
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof(T));
  }
  template <typename T>
  void values(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(v.data(), v.size() * sizeof(T));
  }
  void text(const std::string& s) { bytes(s.data(), s.size()); }
  void info(const ObjectInfo& i) {
    value(i.color), value(i.pass_index), value(i.random);
    values(i.attributes);
  }
  uint64_t result() const { return h_; }

 private:
  void mix(uint64_t w) { h_ = (h_ ^ w) * 0x100000001b3ull; }
  uint64_t h_ = 0xcbf29ce484222325ull;
};

// What a mesh's patches are built from, in object space (patch_cache.h).
void hash_mesh_shape(Hasher& h, const Mesh& m) {
  h.value(m.scheme);
  h.values(m.points);
  h.values(m.face_vertex_counts);
  h.values(m.face_vertex_indices);
  if (m.scheme == SubdivScheme::CatmullClark) {
    h.values(m.crease_vertices);
    h.values(m.crease_sharpness);
    h.values(m.corner_vertices);
    h.values(m.corner_sharpness);
    h.values(m.hole_faces);
    h.value(m.boundary);
  } else {
    h.values(m.corner_normals);
  }
  h.value(m.uv_layers.size());
  for (const auto& layer : m.uv_layers) h.values(layer);
}

}  // namespace

uint64_t mesh_shape_key(const Mesh& m, int uv_layers) {
  Hasher h;
  h.value(uint32_t(1));  // meshes and patch sets never share a key
  h.value(uv_layers);
  hash_mesh_shape(h, m);
  return h.result();
}

uint64_t patch_set_shape_key(const BezierPatches& set, int uv_layers) {
  Hasher h;
  h.value(uint32_t(2));
  h.value(uv_layers);
  h.values(set.control_points);
  h.value(set.round_u);  // a shape flag (MP_PATCH_SHAPE_FLAGS)
  h.value(set.ribbons);
  h.value(set.uv_layers.size());
  for (const auto& layer : set.uv_layers) h.values(layer);
  return h.result();
}

namespace {

// Whether the shadow views run a material's program: it displaces the
// surface or computes its alpha (opacity).
bool program_in_shadows(const Material& m) { return m.program >= 0 && (m.program_displaces || m.program_alpha); }

// Surfaces, materials and images, as the camera's view reads them
// (scene_fingerprint).
void hash_mesh(Hasher& h, const Mesh& m) {
  h.text(m.name), h.value(m.visible_camera);
  hash_mesh_shape(h, m);
  h.value(m.material);
  h.values(m.face_materials);
  h.value(m.object_to_world);
  h.value(m.double_sided);
  h.value(m.texspace_location);
  h.value(m.texspace_size);
  h.value(m.cast_shadows);
  h.info(m.info);
  h.value(m.motion_points.size());
  for (const std::vector<glm::vec3>& step : m.motion_points) h.values(step);
  h.values(m.motion_object_to_world);
}

void hash_patch_set(Hasher& h, const BezierPatches& b) {
  h.values(b.control_points);
  h.value(b.round_u);
  h.value(b.ribbons);
  h.value(b.uv_layers.size());
  for (const auto& layer : b.uv_layers) h.values(layer);
  h.value(b.motion_control_points.size());
  for (const std::vector<glm::vec3>& step : b.motion_control_points) h.values(step);
  h.values(b.motion_object_to_world);
  h.value(b.material);
  h.value(b.object_to_world);
  h.value(b.double_sided);
  h.value(b.visible_camera);
  h.value(b.cast_shadows);
  h.info(b.info);
}

void hash_instances(Hasher& h, const Scene& scene) {
  h.value(scene.prototypes.size());
  for (const Prototype& p : scene.prototypes) {
    h.value(p.meshes.size());
    for (const Mesh& m : p.meshes) hash_mesh(h, m);
    h.value(p.bezier_patches.size());
    for (const BezierPatches& b : p.bezier_patches) hash_patch_set(h, b);
  }
  h.value(scene.instances.size());
  for (const Instance& i : scene.instances) {
    h.value(i.prototype), h.value(i.object_to_world), h.values(i.motion_object_to_world);
    h.info(i.info);
    h.value(i.material), h.value(i.double_sided), h.value(i.visible_camera), h.value(i.cast_shadows);
    h.value(i.reverse_orientation);
  }
}

void hash_surfaces(Hasher& h, const Scene& scene) {
  hash_instances(h, scene);
  h.value(scene.meshes.size());
  for (const Mesh& m : scene.meshes) hash_mesh(h, m);
  h.value(scene.motion_steps);
  h.values(scene.shutter_curve);
  h.values(scene.camera.motion_world_to_camera);
  h.value(scene.bezier_patches.size());
  for (const BezierPatches& b : scene.bezier_patches) hash_patch_set(h, b);
  h.value(scene.materials.size());
  for (const Material& m : scene.materials) {
    h.value(m.opacity);
    h.value(m.program_displaces), h.value(m.displacement_bound), h.value(m.displacement_bound_world);
    h.value(m.program_alpha), h.value(m.program_alpha_cut);
    h.value(m.program), h.value(m.program_shades);
    h.value(m.program_params.size()), h.values(m.program_params);
    h.value(m.model);
    h.value(m.color);
    h.value(m.ka), h.value(m.kd), h.value(m.ks), h.value(m.roughness);
    h.value(m.specular_color), h.value(m.metallic), h.value(m.specular), h.value(m.emission);
  }
  h.value(scene.material_programs.size());
  for (const MaterialProgram& p : scene.material_programs) h.text(p.source);
  h.value(scene.images.size());
  for (const Image& im : scene.images) {
    h.value(im.width), h.value(im.height), h.value(im.srgb);
    h.values(im.pixels);
  }
}

// For shadows only what a shadow view reads counts: the surfaces' shapes,
// placement and motion, the materials' opacity, and the programs that
// displace or compute the alpha, with the node values, object info and
// images those may read. A material's shading edited (its colour, or a node
// tree that only shades) keeps the shadow maps, as do an object's name and
// its camera visibility.
//
// A material as the shadow views see it: its program by its source, not its
// index (the index moves when another material's tree changes).
uint64_t material_shadow_key(const Scene& scene, const Material& m) {
  Hasher h;
  h.value(m.opacity);
  h.value(m.program_displaces), h.value(m.displacement_bound), h.value(m.displacement_bound_world);
  h.value(m.program_alpha), h.value(m.program_alpha_cut);
  if (program_in_shadows(m) && size_t(m.program) < scene.material_programs.size()) {
    h.text(scene.material_programs[size_t(m.program)].source);
    h.value(m.program_params.size()), h.values(m.program_params);
  }
  return h.result();
}

// The materials a surface's faces use, as (index, key) pairs in index
// order; whether any of them runs its program in the shadow views.
bool hash_used_materials(Hasher& h, const Scene& scene, const std::vector<uint64_t>& keys, int material,
                         const std::vector<int>& face_materials) {
  if (face_materials.empty()) {  // one material: no table of them (the same hash as below)
    const bool inside = material >= 0 && size_t(material) < scene.materials.size();
    if (inside) h.value(size_t(material)), h.value(keys[size_t(material)]);
    h.value(!inside);
    return inside && program_in_shadows(scene.materials[size_t(material)]);
  }
  std::vector<bool> used(scene.materials.size(), false);
  bool outside = false;
  auto use = [&](int i) {
    if (i >= 0 && size_t(i) < used.size()) used[size_t(i)] = true;
    else outside = true;
  };
  for (int i : face_materials) use(i);
  bool programs = false;
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i]) {
      h.value(i), h.value(keys[i]);
      programs = programs || program_in_shadows(scene.materials[i]);
    }
  h.value(outside);
  return programs;
}

void hash_light(Hasher& h, const Light& l) {
  h.value(l.type), h.value(l.position), h.value(l.direction);
  h.value(l.cone_angle), h.value(l.cone_delta_angle), h.value(l.beam_distribution);
  h.value(l.shape), h.value(l.axis_u), h.value(l.size_u), h.value(l.size_v);
  h.value(l.cast_shadows), h.value(l.radius), h.value(l.soft_falloff), h.value(l.angle);
}

}  // namespace

ShadowGeometryKeys shadow_geometry_keys(const Scene& scene) {
  ShadowGeometryKeys out;
  std::vector<uint64_t> materials;
  materials.reserve(scene.materials.size());
  bool programs_anywhere = false;
  for (const Material& m : scene.materials) {
    materials.push_back(material_shadow_key(scene, m));
    programs_anywhere = programs_anywhere || program_in_shadows(m);
  }
  // Object info and the texture space enter only where the surface's own
  // materials run a program in the shadow views. `programs` tells whether
  // they do.
  auto mesh_key = [&](const Mesh& m, bool* programs) {
    Hasher h;
    h.value(uint32_t(1));
    hash_mesh_shape(h, m);
    h.values(m.face_materials);
    *programs = hash_used_materials(h, scene, materials, m.material, m.face_materials);
    h.value(m.object_to_world);
    h.value(m.double_sided);
    h.value(m.cast_shadows);
    if (*programs) {
      h.value(m.texspace_location), h.value(m.texspace_size);
      h.info(m.info);
    }
    h.value(m.motion_points.size());
    for (const std::vector<glm::vec3>& step : m.motion_points) h.values(step);
    h.values(m.motion_object_to_world);
    return h.result();
  };
  auto patch_set_key = [&](const BezierPatches& b, bool* programs) {
    Hasher h;
    h.value(uint32_t(2));
    h.values(b.control_points);
    h.value(b.round_u);
    h.value(b.ribbons);
  h.value(b.ribbons);
    h.value(b.motion_control_points.size());
    for (const std::vector<glm::vec3>& step : b.motion_control_points) h.values(step);
    h.values(b.motion_object_to_world);
    *programs = hash_used_materials(h, scene, materials, b.material, {});
    h.value(b.object_to_world);
    h.value(b.double_sided);
    h.value(b.cast_shadows);
    if (*programs) h.info(b.info);
    return h.result();
  };
  bool programs = false;
  out.meshes.reserve(scene.meshes.size());
  for (const Mesh& m : scene.meshes) out.meshes.push_back(mesh_key(m, &programs));
  out.patch_sets.reserve(scene.bezier_patches.size());
  for (const BezierPatches& b : scene.bezier_patches) out.patch_sets.push_back(patch_set_key(b, &programs));
  // Instances: their prototype's surfaces (keyed once per prototype) and
  // their own placement and attributes.
  std::vector<uint64_t> prototype_keys;
  std::vector<bool> prototype_programs;
  for (const Prototype& p : scene.prototypes) {
    Hasher h;
    bool any = false;
    for (const Mesh& m : p.meshes) h.value(mesh_key(m, &programs)), any = any || programs;
    h.value(uint32_t(0));
    for (const BezierPatches& b : p.bezier_patches) h.value(patch_set_key(b, &programs)), any = any || programs;
    prototype_keys.push_back(h.result());
    prototype_programs.push_back(any);
  }
  out.instances.reserve(scene.instances.size());
  for (const Instance& inst : scene.instances) {
    Hasher h;
    h.value(uint32_t(3));
    h.value(prototype_keys[size_t(inst.prototype)]);
    const bool own = inst.material >= 0 && hash_used_materials(h, scene, materials, inst.material, {});
    h.value(inst.material), h.value(inst.double_sided), h.value(inst.cast_shadows), h.value(inst.reverse_orientation);
    h.value(inst.object_to_world);
    h.values(inst.motion_object_to_world);
    if (own || prototype_programs[size_t(inst.prototype)])
      h.info(inst.info);
    out.instances.push_back(h.result());
  }
  Hasher g;
  g.value(scene.motion_steps);
  g.values(scene.shutter_curve);
  g.values(scene.camera.motion_world_to_camera);
  if (programs_anywhere) {
    g.value(scene.images.size());
    for (const Image& im : scene.images) {
      g.value(im.width), g.value(im.height), g.value(im.srgb);
      g.values(im.pixels);
    }
  }
  out.global = g.result();
  return out;
}

uint64_t geometry_fingerprint(const Scene& scene) { return geometry_fingerprint(shadow_geometry_keys(scene)); }

uint64_t geometry_fingerprint(const ShadowGeometryKeys& keys) {
  Hasher h;
  h.value(keys.global);
  h.values(keys.meshes);
  h.values(keys.patch_sets);
  h.values(keys.instances);
  return h.result();
}

uint64_t shadow_light_key(const Light& light, uint64_t geometry_key, const RenderSettings& settings, float z_top) {
  Hasher h;
  h.value(geometry_key);
  hash_light(h, light);
  h.value(settings.shadow_shading_rate), h.value(settings.max_grid_size), h.value(settings.max_split_depth);
  h.value(z_top);
  return h.result();
}

uint64_t world_fingerprint(const Scene& scene) {
  Hasher h;
  const World& w = scene.world;
  h.value(w.program);
  if (w.program >= 0 && size_t(w.program) < scene.material_programs.size())
    h.text(scene.material_programs[size_t(w.program)].source);
  h.value(w.program_params.size()), h.values(w.program_params);
  h.value(w.bake_width), h.value(w.width), h.value(w.height);
  h.values(w.radiance);
  h.value(w.camera), h.value(w.diffuse), h.value(w.glossy), h.value(w.cast_shadows);
  h.value(scene.settings.world_probes);
  if (w.program >= 0) {  // what its Environment Textures read
    h.value(scene.images.size());
    for (const Image& im : scene.images) h.values(im.pixels);
  }
  return h.result();
}

uint64_t scene_fingerprint(const Scene& scene) {
  Hasher h;
  // Device light records include the world's (world_lighting.h).
  h.value(scene.world.present() ? world_fingerprint(scene) : uint64_t(0));
  h.value(scene.camera.world_to_camera);
  hash_surfaces(h, scene);
  h.value(scene.lights.size());
  for (const Light& l : scene.lights) {
    hash_light(h, l);
    h.value(l.color), h.value(l.intensity);
  }
  return h.result();
}

}  // namespace mp
