#include "pipeline/materials/refraction_proxy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "geometry/mp_refract_trace.h"

namespace mp {

namespace {

// A Principled BSDF's transmission line in a program, as node_compiler.py
// writes it: "  p3.transmission = <expression>;", where an unlinked socket's
// value is a literal (programs written before node values became
// parameters) or MP_PARAM(k), the material's value k.
bool principled_transmits(const std::string& source, const std::vector<float>& params) {
  const std::string key = ".transmission = ";
  for (size_t at = source.find(key); at != std::string::npos; at = source.find(key, at + 1)) {
    const size_t start = at + key.size(), end = source.find(';', start);
    const std::string value = source.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (value == "0.0f" || value == "0.0" || value == "0") continue;
    unsigned long k = 0;
    if (std::sscanf(value.c_str(), "MP_PARAM(%lu)", &k) == 1 && value == "MP_PARAM(" + std::to_string(k) + ")" &&
        k < params.size() && params[k] == 0.0f)
      continue;
    return true;
  }
  return false;
}

glm::vec3 centre(const ProxyTriangle& t) { return (t.p[0] + t.p[1] + t.p[2]) / 3.0f; }

// One object's triangles: its patches' surfaces on a steps x steps grid
// each, watertight along shared edges (mp_surface_point), wound so that the
// triangle's own normal agrees with the surface's outward normal.
void tessellate(const PatchBuffer& pb, const std::vector<uint32_t>& patches, int steps,
                std::vector<ProxyTriangle>& out) {
  const uint* info = reinterpret_cast<const uint*>(pb.info.data());
  const int stride = steps + 1;
  std::vector<glm::vec3> p(size_t(stride) * stride), n(p.size());
  for (uint32_t patch : patches) {
    const bool flip = (pb.info[patch].z & MP_PATCH_FLIP_ORIENTATION) != 0u;
    const float4* cp = pb.points.data() + size_t(patch) * MP_PATCH_POINTS;
    for (int j = 0; j <= steps; ++j)
      for (int i = 0; i <= steps; ++i) {
        const float u = float(i) / float(steps), v = float(j) / float(steps);
        float3 P, du, dv;
        const MpPlacement none = mp_placement_none();
        mp_surface_point(pb.points.data(), info, pb.edges.data(), pb.curves.data(), patch, u, v, &none, &P, &du, &dv);
        const float3 nn = mp_patch_normal(cp, pb.info[patch].x, u, v, du, dv, &none);
        p[size_t(j) * stride + i] = P;
        n[size_t(j) * stride + i] = flip ? -nn : nn;
      }
    auto emit = [&](size_t a, size_t b, size_t c) {
      ProxyTriangle t{{p[a], p[b], p[c]}, {n[a], n[b], n[c]}};
      const glm::vec3 g = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
      if (!(glm::dot(g, g) > 0.0f)) return;  // collapsed (a pole's corner)
      if (glm::dot(g, t.n[0] + t.n[1] + t.n[2]) < 0.0f) {
        std::swap(t.p[1], t.p[2]);
        std::swap(t.n[1], t.n[2]);
      }
      out.push_back(t);
    };
    for (int j = 0; j < steps; ++j)
      for (int i = 0; i < steps; ++i) {
        const size_t a = size_t(j) * stride + i, b = a + 1, c = a + stride + 1, d = a + stride;
        emit(a, b, c);
        emit(a, c, d);
      }
  }
}

struct Box {
  glm::vec3 lo{INFINITY}, hi{-INFINITY};
  void grow(const glm::vec3& q) { lo = glm::min(lo, q), hi = glm::max(hi, q); }
};

// Median split along the longest axis of the triangles' centres; leaves of
// at most 4, and at most 24 levels (a leaf below that takes what is left:
// the traversal's stack, MP_REFRACT_STACK, holds depth + 1 entries).
class BvhBuilder {
 public:
  // Triangles are numbered from `tri_base` (those already in `out`).
  BvhBuilder(std::vector<ProxyTriangle>& tris, RefractionProxies& out, size_t tri_base)
      : tris_(tris), out_(out), tri_base_(tri_base) {}

  uint32_t build(size_t first, size_t count, int depth) {
    const uint32_t node = uint32_t(out_.nodes.size() / 2);
    out_.nodes.resize(out_.nodes.size() + 2);
    Box box, centres;
    for (size_t i = first; i < first + count; ++i) {
      for (const glm::vec3& q : tris_[i].p) box.grow(q);
      centres.grow(centre(tris_[i]));
    }
    const glm::vec3 extent = centres.hi - centres.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    uint32_t a, b;
    if (count <= 4 || depth >= 24 || !(extent[axis] > 0.0f)) {
      a = uint32_t(tri_base_ + first);
      b = uint32_t(count) | MP_REFRACT_LEAF;
    } else {
      const size_t half = count / 2;
      std::nth_element(
          tris_.begin() + first, tris_.begin() + first + half, tris_.begin() + first + count,
          [axis](const ProxyTriangle& x, const ProxyTriangle& y) { return centre(x)[axis] < centre(y)[axis]; });
      a = build(first, half, depth + 1);
      b = build(first + half, count - half, depth + 1);
    }
    out_.nodes[2 * size_t(node)] = glm::vec4(box.lo, as_float(a));
    out_.nodes[2 * size_t(node) + 1] = glm::vec4(box.hi, as_float(b));
    return node;
  }

 private:
  std::vector<ProxyTriangle>& tris_;
  RefractionProxies& out_;
  size_t tri_base_;
};

}  // namespace

bool program_refracts(const std::string& source, const std::vector<float>& params) {
  return source.find("mp_add_glass") != std::string::npos || source.find("mp_add_refraction") != std::string::npos ||
         principled_transmits(source, params);
}

RefractionProxies build_refraction_proxies(const PatchBuffer& patches, size_t objects,
                                           const std::vector<bool>& refracts) {
  RefractionProxies out;
  out.roots.assign(objects, MP_REFRACT_NONE);
  std::vector<std::vector<uint32_t>> per_object(objects);
  for (size_t k = 0; k < patches.size(); ++k) {
    const glm::uvec4& info = patches.info[k];
    const size_t object = MP_PATCH_OBJECT(info.z);
    if (object < objects && info.y < refracts.size() && refracts[info.y]) per_object[object].push_back(uint32_t(k));
  }
  size_t total_patches = 0;
  for (const auto& list : per_object) total_patches += list.size();
  if (total_patches == 0) return out;
  // Steps per patch side: two triangles per step squared, within the
  // object's share of the scene's budget (at least one step).
  std::vector<ProxyTriangle> tris;
  for (size_t object = 0; object < objects; ++object) {
    const auto& list = per_object[object];
    if (list.empty()) continue;
    const double share = double(kRefractionTriangleBudget) * double(list.size()) / double(total_patches);
    const double budget = std::min(share, double(kRefractionObjectTriangles));
    // Too many patches for even one step each: no proxy (the shade falls
    // back to one environment lookup, mp_refracted_exit).
    if (budget < 2.0 * double(list.size())) continue;
    const int steps = std::clamp(int(std::sqrt(budget / (2.0 * double(list.size())))), 1, 8);
    tris.clear();
    tessellate(patches, list, steps, tris);
    if (tris.empty()) continue;
    out.roots[object] = append_refraction_proxy(tris, out);
  }
  return out;
}

uint32_t append_refraction_proxy(std::vector<ProxyTriangle>& tris, RefractionProxies& out) {
  BvhBuilder builder(tris, out, out.tris.size() / 6);
  const uint32_t root = builder.build(0, tris.size(), 0);
  for (const ProxyTriangle& t : tris) {
    for (const glm::vec3& q : t.p) out.tris.emplace_back(q, 0.0f);
    for (const glm::vec3& q : t.n) out.tris.emplace_back(q, 0.0f);
  }
  return root;
}

}  // namespace mp
