#include "pipeline/device_scene/instance_placement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include "micropoly/error.h"
#include "geometry/mp_patch.h"
#include "pipeline/device_scene/patch_tree.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "pipeline/device_scene/shape_placement.h"
#include "scene/orientation.h"

namespace mp {
namespace {

// Prototype patches carry no object of their own: their instances' records
// name one (mp_placed_flags), and the refraction proxies skip them.
constexpr uint32_t kNoObject = 0xffffffu;

// A variant's patches and what its instances read of them.
struct Variant {
  uint32_t first = 0, count = 0;
  PatchTree tree;
  glm::vec3 lo{3e38f}, hi{-3e38f};  // its patches' box, displacement included (its own space)
  glm::vec3 texspace_location{0.0f}, texspace_size{0.0f};
  glm::mat4 to_prototype{1.0f};
  float world_fix = 1.0f;  // world-unit displacement bounds over the least scale of its placements
};

void rows(const glm::dmat4& m, float* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = float(m[c][r]);
}

glm::vec3 corner(const Variant& v, int k) {
  return {(k & 1) ? v.hi.x : v.lo.x, (k & 2) ? v.hi.y : v.lo.y, (k & 4) ? v.hi.z : v.lo.z};
}

glm::vec3 apply(const glm::dmat4& m, glm::vec3 p) { return glm::vec3(m * glm::dvec4(glm::dvec3(p), 1.0)); }

}  // namespace

PrototypeVariants prototype_variants(const Scene& scene) {
  PrototypeVariants out;
  std::map<std::tuple<int, int, int, int, bool>, uint32_t> index;
  out.of_instance.reserve(scene.instances.size());
  for (const Instance& inst : scene.instances) {
    const Prototype& proto = scene.prototypes[size_t(inst.prototype)];
    std::vector<uint32_t> mine;
    const int surfaces = int(proto.meshes.size() + proto.bezier_patches.size());
    for (int s = 0; s < surfaces; ++s) {
      const auto key = std::make_tuple(inst.prototype, s, inst.material, inst.double_sided, inst.reverse_orientation);
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, uint32_t(out.surfaces.size())).first;
        auto adapt = [&](auto& surface) {
          if (inst.material >= 0) surface.material = inst.material;
          if (inst.double_sided >= 0) surface.double_sided = inst.double_sided == 1;
        };
        if (size_t(s) < proto.meshes.size()) {
          Mesh m = proto.meshes[size_t(s)];
          adapt(m);
          if (inst.reverse_orientation) reverse_faces(m);
          out.meshes.push_back(std::move(m));
          out.surfaces.push_back({&out.meshes.back(), nullptr});
        } else {
          BezierPatches b = proto.bezier_patches[size_t(s) - proto.meshes.size()];
          adapt(b);
          if (inst.reverse_orientation) mirror_patches_u(b);
          out.sets.push_back(std::move(b));
          out.surfaces.push_back({nullptr, &out.sets.back()});
        }
      }
      mine.push_back(it->second);
    }
    out.of_instance.push_back(std::move(mine));
  }
  return out;
}

void place_instances(const Scene& scene, const PrototypeVariants& pv,
                     const std::vector<std::shared_ptr<const PatchBuffer>>& shapes, HostSceneData& out) {
  const size_t steps = scene.motion_steps >= 2 ? size_t(scene.motion_steps) : 0;
  const glm::dmat4 w2c(scene.camera.world_to_camera);
  auto camera_at = [&](size_t k) {
    return scene.camera.motion_world_to_camera.empty() ? w2c : glm::dmat4(scene.camera.motion_world_to_camera[k]);
  };
  // Each instance's surfaces to camera space, and the least scale a
  // variant is placed at (for bounds of displacement in world units).
  std::vector<Variant> variants(pv.surfaces.size());
  for (size_t v = 0; v < variants.size(); ++v)
    variants[v].to_prototype = pv.surfaces[v].mesh ? pv.surfaces[v].mesh->object_to_world
                                                   : pv.surfaces[v].set->object_to_world;
  for (size_t i = 0; i < scene.instances.size(); ++i)
    for (uint32_t v : pv.of_instance[i]) {
      const glm::dmat3 linear(w2c * glm::dmat4(scene.instances[i].object_to_world) * glm::dmat4(variants[v].to_prototype));
      const glm::dmat3 inv = glm::inverse(linear);
      double frobenius = 0.0;
      for (int c = 0; c < 3; ++c) frobenius += glm::dot(inv[c], inv[c]);
      variants[v].world_fix = std::max(variants[v].world_fix, float(std::sqrt(frobenius)));
    }
  // The variants' patches, in their own space.
  const size_t own_points = out.patches.points.size(), own_curves = out.patches.curves.size();
  for (size_t v = 0; v < variants.size(); ++v) {
    const Mesh* mesh = pv.surfaces[v].mesh;
    const BezierPatches* set = pv.surfaces[v].set;
    Variant& var = variants[v];
    var.first = uint32_t(out.patches.size());
    place_shape(*shapes[v], glm::mat4(1.0f), mesh, set, kNoObject, scene, out.patches);
    var.count = uint32_t(out.patches.size() - var.first);
    std::vector<glm::vec3> boxes(2 * size_t(var.count));
    for (uint32_t p = var.first; p < var.first + var.count; ++p) {
      glm::vec4* cp = &out.patches.points[size_t(p) * MP_PATCH_POINTS];
      const uint32_t material = out.patches.info[p].y;
      if (material < scene.materials.size() && scene.materials[material].displacement_bound_world)
        cp[0].w *= var.world_fix;  // the bound in the least-scaled placement's units
      glm::vec3 lo(3e38f), hi(-3e38f);
      for (int k = 0; k < MP_PATCH_POINTS; ++k) {
        lo = glm::min(lo, glm::vec3(cp[k]) - glm::vec3(cp[0].w));
        hi = glm::max(hi, glm::vec3(cp[k]) + glm::vec3(cp[0].w));
      }
      boxes[2 * (p - var.first)] = lo, boxes[2 * (p - var.first) + 1] = hi;
      var.lo = glm::min(var.lo, lo), var.hi = glm::max(var.hi, hi);
    }
    if (var.count > 0) {
      var.tree = build_patch_tree(boxes, var.first, out.patch_nodes);
      out.tree_depth = std::max(out.tree_depth, var.tree.depth);
    }
    const std::vector<glm::vec3>& points = mesh ? mesh->points : set->control_points;
    if (mesh) var.texspace_location = mesh->texspace_location, var.texspace_size = mesh->texspace_size;
    if (var.texspace_size == glm::vec3(0.0f) && !points.empty()) {
      glm::vec3 lo(3e38f), hi(-3e38f);
      for (const glm::vec3& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
      var.texspace_location = 0.5f * (lo + hi);
      var.texspace_size = 0.5f * (hi - lo);
    }
  }
  // One record per instance and surface.
  struct Placed {
    DeviceInstance record{};
    glm::mat4 to_camera{1.0f}, to_world{1.0f};
    uint32_t variant = 0;
    size_t instance = 0;
    std::vector<glm::vec4> motion;  // 3 rows per step
  };
  std::vector<Placed> placed;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    for (uint32_t v : pv.of_instance[i]) {
      const Variant& var = variants[v];
      if (var.count == 0) continue;
      Placed p;
      p.variant = v, p.instance = i;
      const glm::dmat4 to_world = glm::dmat4(inst.object_to_world) * glm::dmat4(var.to_prototype);
      const glm::dmat4 m = w2c * to_world;
      p.to_camera = glm::mat4(m), p.to_world = glm::mat4(to_world);
      DeviceInstance& r = p.record;
      rows(m, r.to_camera);
      const glm::dmat3 normal = glm::transpose(glm::inverse(glm::dmat3(m)));
      for (int row = 0; row < 3; ++row)
        for (int c = 0; c < 3; ++c) r.normal_to_camera[4 * row + c] = float(normal[c][row]);
      r.flags = (glm::determinant(glm::dmat3(m)) < 0.0 ? MP_PATCH_FLIP_ORIENTATION : 0u) |
                (inst.visible_camera ? 0u : MP_PATCH_NO_CAMERA) | (inst.cast_shadows ? 0u : MP_PATCH_NO_SHADOW);
      r.root = var.tree.root;
      glm::vec3 lo(3e38f), hi(-3e38f), reach(0.0f);
      for (int k = 0; k < 8; ++k) {
        const glm::vec3 c = apply(m, corner(var, k));
        lo = glm::min(lo, c), hi = glm::max(hi, c);
      }
      for (size_t k = 0; k < steps; ++k) {
        const glm::dmat4 at = camera_at(k) *
                              glm::dmat4(inst.motion_object_to_world.empty() ? inst.object_to_world
                                                                             : inst.motion_object_to_world[k]) *
                              glm::dmat4(var.to_prototype);
        float step_rows[12];
        rows(at, step_rows);
        for (int row = 0; row < 3; ++row)
          p.motion.emplace_back(step_rows[4 * row], step_rows[4 * row + 1], step_rows[4 * row + 2], step_rows[4 * row + 3]);
        for (int c = 0; c < 8; ++c) {
          const glm::vec3 moved = apply(at, corner(var, c));
          lo = glm::min(lo, moved), hi = glm::max(hi, moved);
          reach = glm::max(reach, glm::abs(moved - apply(m, corner(var, c))));
        }
      }
      for (int a = 0; a < 3; ++a) r.box_lo[a] = lo[a], r.box_hi[a] = hi[a], r.reach[a] = reach[a];
      placed.push_back(std::move(p));
    }
  }
  // Nearest the camera first, so that instances' roots (taken in order)
  // fill the occlusion pyramid front to back.
  std::stable_sort(placed.begin(), placed.end(),
                   [](const Placed& a, const Placed& b) { return a.record.box_hi[2] > b.record.box_hi[2]; });
  if (out.own_patches + placed.size() > UINT32_MAX)
    throw Error("the scene places " + std::to_string(placed.size()) +
                " instances' surfaces, more than 2^32 in all: use fewer instances");
  for (Placed& p : placed) {
    const Variant& var = variants[p.variant];
    p.record.object = uint32_t(out.objects.size());
    out.add_object(to_device_object(p.to_camera, p.to_world, var.texspace_location, var.texspace_size, {},
                                    scene.instances[p.instance].info),
                   scene.instances[p.instance].info);
    out.instanced_patches += var.count;
    out.instances.push_back(p.record);
  }
  out.root_count = out.own_patches + out.instances.size();
  if (out.objects.size() > kNoObject)
    throw Error("the scene has " + std::to_string(out.objects.size()) + " objects and instances' surfaces, more than " +
                std::to_string(kNoObject));
  if (steps == 0) return;
  // Motion rows, step after step; and each step's points and edge curves
  // laid out as the patches are, the prototypes' (which do not move) after
  // the own patches'.
  out.instance_motion.resize(3 * steps * placed.size());
  for (size_t i = 0; i < placed.size(); ++i)
    for (size_t k = 0; k < steps; ++k)
      for (size_t row = 0; row < 3; ++row)
        out.instance_motion[3 * (k * placed.size() + i) + row] = placed[i].motion[3 * k + row];
  auto relayout = [&](std::vector<glm::vec4>& moving, size_t own, const std::vector<glm::vec4>& all) {
    std::vector<glm::vec4> laid;
    laid.reserve(steps * all.size());
    for (size_t k = 0; k < steps; ++k) {
      laid.insert(laid.end(), moving.begin() + long(k * own), moving.begin() + long((k + 1) * own));
      laid.insert(laid.end(), all.begin() + long(own), all.end());
    }
    moving = std::move(laid);
  };
  relayout(out.motion_points, own_points, out.patches.points);
  relayout(out.motion_curves, own_curves, out.patches.curves);
}

}  // namespace mp
