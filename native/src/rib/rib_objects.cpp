// Placing primitives into the Scene, and retained objects (ObjectBegin/End,
// ObjectInstance; RI spec 3.2, section 5.8).
//
// Orientation: a Scene mesh's front side is the one from which its faces
// appear counter-clockwise under the right-hand rule in its own object
// coordinates; the renderer keeps that side in front under mirroring
// transformations. RenderMan's front side is, in the same object
// coordinates, the side its normal dPdu x dPdv (for polygons: the plane
// normal towards a viewer who sees the vertices clockwise in left-handed
// terms, i.e. the same cross product) points to, flipped when the current
// orientation differs from the coordinate system's handedness. Both
// conventions compute the same cross product of the same numbers, so faces
// keep their order unless the RenderMan normal is flipped ("inside_out"),
// in which case face loops are reversed (and patches mirrored in u).
#include <algorithm>

#include "rib/rib_parser.h"
#include "scene/orientation.h"

namespace mp::rib {
namespace {

// Appends UV layers `src` (src_count values each) to `dst` (dst_count each);
// a layer one side lacks reads zeros there, as a missing layer does.
void append_layers(std::vector<std::vector<glm::vec2>>& dst, size_t dst_count,
                   const std::vector<std::vector<glm::vec2>>& src, size_t src_count) {
  const size_t layers = std::max(dst.size(), src.size());
  dst.resize(layers, std::vector<glm::vec2>(dst_count, glm::vec2(0.0f)));
  for (size_t k = 0; k < layers; ++k) {
    if (k < src.size())
      dst[k].insert(dst[k].end(), src[k].begin(), src[k].end());
    else
      dst[k].resize(dst_count + src_count, glm::vec2(0.0f));
  }
}

void append_uv_layers(Mesh& dst, size_t dst_corners, const Mesh& src) {
  append_layers(dst.uv_layers, dst_corners, src.uv_layers, src.face_vertex_indices.size());
}

// Appends a patch primitive's corner UVs to the set it joins, which had
// `first` patches before it.
void append_patch_uvs(BezierPatches& dst, size_t first, const Primitive& prim) {
  append_layers(dst.uv_layers, 4 * first, prim.patch_uvs, prim.patch_points.size() / 4);
}

// Appends `src`'s corner normals; when only one side has them, the other's
// corners get their face's normal (flat), so both shade as they would alone.
void append_corner_normals(Mesh& dst, const Mesh& src) {
  if (dst.corner_normals.empty() && src.corner_normals.empty()) return;
  auto flat = [](const Mesh& m, std::vector<glm::vec3>& out) {
    size_t c = 0;
    for (size_t f = 0; f < m.face_vertex_counts.size(); ++f) {
      const size_t n = static_cast<size_t>(m.face_vertex_counts[f]);
      glm::vec3 normal(0.0f);  // Newell's method: any simple polygon
      for (size_t k = 0; k < n; ++k) {
        const glm::vec3 a = m.points[static_cast<size_t>(m.face_vertex_indices[c + k])];
        const glm::vec3 b = m.points[static_cast<size_t>(m.face_vertex_indices[c + (k + 1) % n])];
        normal += glm::vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
      }
      out.insert(out.end(), n, normal);
      c += n;
    }
  };
  const size_t dst_faces = dst.face_vertex_counts.size() - src.face_vertex_counts.size();
  if (dst.corner_normals.empty()) {
    std::vector<glm::vec3> normals;
    Mesh before = dst;  // the faces dst had before this append
    before.face_vertex_counts.resize(dst_faces);
    flat(before, normals);
    dst.corner_normals = std::move(normals);
  }
  if (src.corner_normals.empty())
    flat(src, dst.corner_normals);
  else
    dst.corner_normals.insert(dst.corner_normals.end(), src.corner_normals.begin(), src.corner_normals.end());
}

}  // namespace

void Parser::place(Primitive prim, const ArgReader& args) {
  const int line = args.request().line;
  if (defining_active_) {
    // Stored relative to the object definition's own coordinate system.
    prim.local = attrs_.ctm * prim.local;
    charge(prim.elements(), line);
    definition_.prims.push_back(std::move(prim));
    return;
  }
  if (!in_world_) args.fail("geometry outside WorldBegin/WorldEnd");
  add_to_scene(prim, attrs_.ctm, attrs_, line);
}

void Parser::account_lights(const Attributes& attrs) {
  for (size_t i = 0; i < lights_.size(); ++i) {
    if (i < attrs.lights_on.size() && attrs.lights_on[i])
      lights_[i].on_some = true;
    else
      lights_[i].off_some = true;
  }
}

// What every primitive and instance does to the parser's accounts: the
// lights it is lit by, and the one shading rate.
void Parser::note_primitive(const Attributes& attrs, int line) {
  account_lights(attrs);
  ++prims_emitted_;
  // ShadingRate is an attribute in RenderMan but one global setting here.
  const float rate = result_.scene.settings.shading_rate;
  if (!shading_rate_used_) {
    shading_rate_used_ = true;
    shading_rate_at_use_ = rate;
  } else if (rate != shading_rate_at_use_) {
    warn_once("shading-rate", line,
              "ShadingRate differs between primitives; one rate (the last one set) is used");
  }
}

void Parser::add_to_scene(const Primitive& prim, const glm::mat4& xform, const Attributes& attrs,
                          int line) {
  charge(prim.elements(), line);
  const glm::mat4 object_to_world = xform * prim.local;
  const int material = material_index(attrs);
  note_primitive(attrs, line);
  const bool flip = attrs.inside_out;
  const std::string name = attrs.has_identifier ? attrs.identifier : prim.origin;
  Scene& scene = result_.scene;

  // Runs of Polygon or Patch requests with the same state share one object.
  const bool moving = !attrs.motion_ctm.empty();
  const bool merge = prim.mergeable && !moving && has_merge_target_ && merge_.kind == prim.kind &&
                     merge_.object_to_world == object_to_world && merge_.material == material &&
                     merge_.double_sided == attrs.double_sided && merge_.round_u == attrs.round_u &&
                     merge_.ribbons == attrs.ribbons &&
                     merge_.visible_camera == attrs.visible_camera &&
                     merge_.cast_shadows == attrs.cast_shadows && merge_.object_info == attrs.object_info &&
                     merge_.identifier == attrs.identifier &&
                     merge_.has_identifier == attrs.has_identifier;
  if (prim.kind == Primitive::Kind::Mesh) {
    if (merge) {
      Mesh& dst = scene.meshes[merge_.index];
      const int base = static_cast<int>(dst.points.size());
      const size_t first_face = dst.face_vertex_counts.size();
      const size_t first_index = dst.face_vertex_indices.size();
      dst.points.insert(dst.points.end(), prim.mesh.points.begin(), prim.mesh.points.end());
      dst.face_vertex_counts.insert(dst.face_vertex_counts.end(),
                                    prim.mesh.face_vertex_counts.begin(),
                                    prim.mesh.face_vertex_counts.end());
      for (int i : prim.mesh.face_vertex_indices) dst.face_vertex_indices.push_back(base + i);
      append_uv_layers(dst, first_index, prim.mesh);
      append_corner_normals(dst, prim.mesh);
      if (flip) reverse_faces(dst, first_face, first_index);
      return;
    }
    Mesh mesh = prim.mesh;
    mesh.name = name;
    mesh.object_to_world = object_to_world;
    mesh.material = material;
    mesh.double_sided = attrs.double_sided;
    mesh.visible_camera = attrs.visible_camera;
    mesh.cast_shadows = attrs.cast_shadows;
    mesh.info = attrs.object_info;
    for (const glm::mat4& m : attrs.motion_ctm) mesh.motion_object_to_world.push_back(m * prim.local);
    if (flip) reverse_faces(mesh, 0, 0);
    scene.meshes.push_back(std::move(mesh));
  } else {
    if (merge) {
      BezierPatches& dst = scene.bezier_patches[merge_.index];
      const size_t first = dst.control_points.size() / 16;
      dst.control_points.insert(dst.control_points.end(), prim.patch_points.begin(),
                                prim.patch_points.end());
      append_patch_uvs(dst, first, prim);
      if (flip) mirror_patches_u(dst, first);
      return;
    }
    if (moving)
      warn_once("motion-patches", line, "patches (Patch, PatchMesh) do not move: they render at the shutter's centre");
    BezierPatches set;
    set.name = name;
    set.control_points = prim.patch_points;
    set.uv_layers = prim.patch_uvs;
    set.object_to_world = object_to_world;
    set.material = material;
    set.double_sided = attrs.double_sided;
    set.round_u = attrs.round_u;
    set.ribbons = attrs.ribbons;
    set.visible_camera = attrs.visible_camera;
    set.cast_shadows = attrs.cast_shadows;
    set.info = attrs.object_info;
    if (flip) mirror_patches_u(set, 0);
    scene.bezier_patches.push_back(std::move(set));
  }
  has_merge_target_ = prim.mergeable && !moving;
  if (has_merge_target_) {
    merge_.kind = prim.kind;
    merge_.index = prim.kind == Primitive::Kind::Mesh ? scene.meshes.size() - 1
                                                      : scene.bezier_patches.size() - 1;
    merge_.object_to_world = object_to_world;
    merge_.material = material;
    merge_.double_sided = attrs.double_sided;
    merge_.round_u = attrs.round_u;
    merge_.ribbons = attrs.ribbons;
    merge_.visible_camera = attrs.visible_camera;
    merge_.cast_shadows = attrs.cast_shadows;
    merge_.object_info = attrs.object_info;
    merge_.identifier = attrs.identifier;
    merge_.has_identifier = attrs.has_identifier;
  }
}

void Parser::req_object_begin(ArgReader& args) {
  const std::string key = handle_key(args);
  args.done();
  if (defining_active_) args.fail("nested ObjectBegin");
  push_block(Block::Kind::Object, args.request().line);
  defining_active_ = true;
  defining_ = key;
  definition_ = ObjectDef{};
  // The object is defined in its own coordinate system; ObjectInstance
  // places it with the transformation current at the instance.
  attrs_.ctm = glm::mat4(1.0f);
}

void Parser::req_object_end(ArgReader& args) {
  pop_block(Block::Kind::Object, args);
  objects_[defining_] = std::move(definition_);
  definition_ = ObjectDef{};
  defining_active_ = false;
}

void Parser::req_object_instance(ArgReader& args) {
  const std::string key = handle_key(args);
  args.done();
  const int line = args.request().line;
  auto it = objects_.find(key);
  if (it == objects_.end()) args.fail("unknown object handle " + key);
  const std::vector<Primitive>& prims = it->second.prims;
  if (defining_active_) {
    // An instance inside a definition: copy, composing the transformations.
    for (const Primitive& p : prims) {
      Primitive copy = p;
      copy.local = attrs_.ctm * p.local;
      charge(copy.elements(), line);
      definition_.prims.push_back(std::move(copy));
    }
    return;
  }
  if (!in_world_) args.fail("ObjectInstance outside WorldBegin/WorldEnd");
  add_instance(it->second, key, line);
}

// An object's prototype is made at its first instance (definitions never
// placed cost nothing); every instance is then one Scene Instance. Instances
// take the attributes (material, sides, orientation, visibility) current
// here, as the RI specification has it; attributes set inside the
// definition do not apply to it.
void Parser::add_instance(ObjectDef& def, const std::string& key, int line) {
  Scene& scene = result_.scene;
  if (def.prototype < 0) {
    Prototype proto;
    proto.name = key;
    for (const Primitive& p : def.prims) {
      if (p.kind == Primitive::Kind::Mesh) {
        Mesh mesh = p.mesh;
        mesh.name = p.origin;
        mesh.object_to_world = p.local;
        proto.meshes.push_back(std::move(mesh));
      } else {
        BezierPatches set;
        set.name = p.origin;
        set.control_points = p.patch_points;
        set.uv_layers = p.patch_uvs;
        set.object_to_world = p.local;
        proto.bezier_patches.push_back(std::move(set));
      }
    }
    def.prototype = int(scene.prototypes.size());
    scene.prototypes.push_back(std::move(proto));
  }
  charge(1, line);
  note_primitive(attrs_, line);
  Instance inst;
  inst.name = attrs_.has_identifier ? attrs_.identifier : key;
  inst.prototype = def.prototype;
  inst.object_to_world = attrs_.ctm;
  inst.material = material_index(attrs_);
  inst.double_sided = attrs_.double_sided ? 1 : 0;
  inst.visible_camera = attrs_.visible_camera;
  inst.cast_shadows = attrs_.cast_shadows;
  inst.info = attrs_.object_info;
  inst.reverse_orientation = attrs_.inside_out;
  inst.motion_object_to_world = attrs_.motion_ctm;
  if (!inst.motion_object_to_world.empty() && !scene.prototypes[size_t(def.prototype)].bezier_patches.empty())
    warn_once("motion-patches", line, "patches (Patch, PatchMesh) do not move: they render at the shutter's centre");
  scene.instances.push_back(std::move(inst));
  has_merge_target_ = false;
}

}  // namespace mp::rib
