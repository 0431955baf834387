// Shared edge curves: what makes neighbouring patches dice watertight.
//
// Two patches that meet along an edge hold their own copies of its control
// points, computed by different formulas (OpenSubdiv's B-spline to Bezier
// conversion from either side, Gregory end caps, degree elevation of
// polygons), so they agree only to rounding. The dicer evaluates every point
// on a patch boundary from one stored curve per edge instead (mp_surface.h):
// here the corner points of a surface are welded to one representative each,
// edges with the same end points and nearly the same inner points get one
// curve, and an edge whose other side is two half-length edges (adaptive
// refinement's transitions between levels; a quad next to a split n-gon)
// refers to the two half curves. Each curve also carries a cubic through the
// surface normal along it (sampled from the patch that first had the edge),
// so displacement moves shared edge vertices identically from both sides.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/mp_compat.h"
#include "geometry/mp_patch.h"
#include "core/mp_types.h"
#include "geometry/mp_patch_eval.h"
#include "geometry/mp_surface.h"
#include "subdiv/patch_buffer.h"

namespace mp {
namespace {

// Control point indices of edge e in its parameter's direction (mp_patch.h).
constexpr int kEdgePoints[4][4] = {{0, 1, 2, 3}, {3, 7, 11, 15}, {12, 13, 14, 15}, {0, 4, 8, 12}};
constexpr int kCorners[4] = {0, 3, 12, 15};

// Points within `tol` (max norm) of a representative become that
// representative. A hash grid of cells 4 * tol wide; a point is compared with
// the cells it is within tol of.
class PointWelder {
 public:
  explicit PointWelder(float tol) : tol_(tol), cell_(4.0 * double(tol)) {}

  uint32_t weld(const glm::vec3& p) {
    long long c[3];
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      double x = double(p[a]) / cell_;
      c[a] = static_cast<long long>(std::floor(x));
      double frac = (x - std::floor(x)) * cell_;
      lo[a] = frac < tol_ ? -1 : 0;
      hi[a] = cell_ - frac < tol_ ? 1 : 0;
    }
    for (int dz = lo[2]; dz <= hi[2]; ++dz)
      for (int dy = lo[1]; dy <= hi[1]; ++dy)
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          auto it = cells_.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == cells_.end()) continue;
          for (uint32_t id : it->second) {
            glm::vec3 d = glm::abs(reps_[id] - p);
            if (std::max(d.x, std::max(d.y, d.z)) <= tol_) return id;
          }
        }
    const uint32_t id = uint32_t(reps_.size());
    reps_.push_back(p);
    cells_[key(c[0], c[1], c[2])].push_back(id);
    return id;
  }
  const glm::vec3& rep(uint32_t id) const { return reps_[id]; }

 private:
  static uint64_t key(long long x, long long y, long long z) {
    uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull;
    h ^= uint64_t(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= uint64_t(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return h;
  }
  float tol_;
  double cell_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
  std::vector<glm::vec3> reps_;
};

struct Curve {
  glm::vec3 p[4];       // in its own direction; p[0], p[3] are welded corners
  uint32_t start, end;  // corner representatives
  int users = 0;
  size_t owner = 0;     // the patch whose edge `owner_edge` created it, in its direction
  int owner_edge = 0;
};

uint64_t pair_key(uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); }

float max_distance(const glm::vec3& a, const glm::vec3& b) {
  glm::vec3 d = glm::abs(a - b);
  return std::max(d.x, std::max(d.y, d.z));
}

// Does `q` (start..end in its own direction) trace curve c, forwards or
// backwards? Inner points must agree within `tol`. Returns 0 = no, 1 =
// forwards, 2 = backwards.
int same_curve(const Curve& c, uint32_t q_start, uint32_t q_end, const glm::vec3* q, float tol) {
  if (c.start == q_start && c.end == q_end && max_distance(c.p[1], q[1]) <= tol && max_distance(c.p[2], q[2]) <= tol)
    return 1;
  if (c.start == q_end && c.end == q_start && max_distance(c.p[1], q[2]) <= tol && max_distance(c.p[2], q[1]) <= tol)
    return 2;
  return 0;
}

// The halves of a cubic Bezier curve at t = 1/2 (de Casteljau).
void halve(const glm::vec3* p, glm::vec3* first, glm::vec3* second) {
  glm::dvec3 a(p[0]), b(p[1]), c(p[2]), d(p[3]);
  glm::dvec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), cd = 0.5 * (c + d);
  glm::dvec3 abc = 0.5 * (ab + bc), bcd = 0.5 * (bc + cd), m = 0.5 * (abc + bcd);
  first[0] = p[0], first[1] = glm::vec3(ab), first[2] = glm::vec3(abc), first[3] = glm::vec3(m);
  second[0] = glm::vec3(m), second[1] = glm::vec3(bcd), second[2] = glm::vec3(cd), second[3] = p[3];
}

// A coarse patch edge whose other side is two half edges meeting at corner `middle`.
struct Transition {
  size_t patch;
  int edge;
  uint32_t middle;
};

// Corner UVs made bit-identical where patches meet, so that the device's UV
// on a shared edge (mp_patch_uv) is the same from both sides: UVs of one
// welded corner that agree within rounding take one value (UV seams, where
// they differ, stay apart), and the half edges of a transition take, at
// their shared corner, exactly the midpoint the coarse side computes.
void share_corner_uvs(PatchBuffer& buffer, size_t first, const std::vector<uint32_t>& corner_rep,
                      const std::vector<Transition>& transitions) {
  const int layers = buffer.uv_layers;
  if (layers == 0) return;
  // Counter-clockwise corner c of a patch: (0,0), (1,0), (1,1), (0,1); its
  // index in corner_rep (which follows kCorners) and the edges' end corners.
  constexpr int kRepIndex[4] = {0, 1, 3, 2};
  constexpr int kEdgeEnds[4][2] = {{0, 1}, {1, 2}, {3, 2}, {0, 3}};
  auto uv = [&](size_t p, int layer, int c) -> glm::vec4& { return buffer.uvs[(p * size_t(layers) + size_t(layer)) * 2 + size_t(c >> 1)]; };
  auto get = [&](size_t p, int layer, int c) { glm::vec4& q = uv(p, layer, c); return (c & 1) ? glm::vec2(q.z, q.w) : glm::vec2(q.x, q.y); };
  auto set = [&](size_t p, int layer, int c, glm::vec2 v) {
    glm::vec4& q = uv(p, layer, c);
    if (c & 1) q.z = v.x, q.w = v.y;
    else q.x = v.x, q.y = v.y;
  };
  auto close = [](glm::vec2 a, glm::vec2 b) {
    glm::vec2 d = glm::abs(a - b);
    float scale = std::max(1.0f, std::max(std::max(std::abs(a.x), std::abs(a.y)), std::max(std::abs(b.x), std::abs(b.y))));
    return std::max(d.x, d.y) <= 1e-5f * scale;
  };
  // Distinct UVs kept per corner and layer. Real meshes meet a vertex with a
  // handful of UV islands; a vertex shared by thousands of faces with
  // different UVs each (a fan, or input built to be slow) would make the
  // search quadratic, so past this many its values are left as they are.
  constexpr size_t kMaxUvsPerCorner = 32;
  auto snap = [&](std::unordered_map<uint64_t, std::vector<glm::vec2>>& values, bool add) {
    for (size_t p = first; p < buffer.size(); ++p)
      for (int layer = 0; layer < layers; ++layer)
        for (int c = 0; c < 4; ++c) {
          const uint64_t key = (uint64_t(corner_rep[(p - first) * 4 + size_t(kRepIndex[c])]) << 8) | uint64_t(layer);
          auto it = values.find(key);
          const glm::vec2 v = get(p, layer, c);
          if (it != values.end() && it->second.size() > kMaxUvsPerCorner) continue;
          if (it != values.end()) {
            auto same = std::find_if(it->second.begin(), it->second.end(), [&](glm::vec2 w) { return close(v, w); });
            if (same != it->second.end()) {
              set(p, layer, c, *same);
              continue;
            }
          }
          if (add) values[key].push_back(v);
        }
  };
  std::unordered_map<uint64_t, std::vector<glm::vec2>> welded, midpoints;
  snap(welded, true);
  for (const Transition& t : transitions)
    for (int layer = 0; layer < layers; ++layer) {
      const glm::vec2 a = get(t.patch, layer, kEdgeEnds[t.edge][0]), b = get(t.patch, layer, kEdgeEnds[t.edge][1]);
      midpoints[(uint64_t(t.middle) << 8) | uint64_t(layer)].push_back(a + (b - a) * 0.5f);  // as mp_patch_uv
    }
  snap(midpoints, false);
}

}  // namespace

void share_patch_edges(PatchBuffer& buffer, size_t first) {
  const size_t count = buffer.size() - first;
  buffer.edges.resize(buffer.size() * MP_EDGE_REFS, MP_NO_CURVE);
  if (count == 0) return;
  // Ribbons turn to face each view and evaluate their edges themselves
  // (mp_ribbon.h): no curves, no welding. Each edge names curve 0 forwards,
  // which only tells mp_patch_uv to interpolate along the edge's own
  // direction.
  bool ribbons = true;
  for (size_t p = first; p < buffer.size() && ribbons; ++p) ribbons = buffer.info[p].x == MP_PATCH_CURVE;
  if (ribbons) {
    for (size_t p = first; p < buffer.size(); ++p)
      for (int e = 0; e < 4; ++e) buffer.edges[p * MP_EDGE_REFS + 2 * size_t(e)] = 0u;
    return;
  }
  auto point = [&](size_t patch, int k) -> glm::vec4& { return buffer.points[patch * MP_PATCH_POINTS + size_t(k)]; };

  // Welding tolerance: a few float steps at the surface's scale and distance.
  glm::vec3 lo(3e38f), hi(-3e38f);
  float far = 0.0f;
  for (size_t p = first; p < buffer.size(); ++p)
    for (int k : kCorners) {
      glm::vec3 q(point(p, k));
      lo = glm::min(lo, q), hi = glm::max(hi, q);
      far = std::max(far, std::max(std::abs(q.x), std::max(std::abs(q.y), std::abs(q.z))));
    }
  const float scale = std::max(far, std::max(hi.x - lo.x, std::max(hi.y - lo.y, hi.z - lo.z)));
  const float tol = std::max(1e-6f * scale, 1e-30f);

  // 1. One representative per corner point, written back into the patches.
  PointWelder welder(tol);
  std::vector<uint32_t> corner_rep(count * 4);
  for (size_t p = first; p < buffer.size(); ++p)
    for (int c = 0; c < 4; ++c) {
      glm::vec4& q = point(p, kCorners[c]);
      uint32_t id = welder.weld(glm::vec3(q));
      corner_rep[(p - first) * 4 + size_t(c)] = id;
      q = glm::vec4(welder.rep(id), q.w);
    }
  auto rep_of = [&](size_t p, int cp) {
    const int c = cp == 0 ? 0 : cp == 3 ? 1 : cp == 12 ? 2 : 3;
    return corner_rep[(p - first) * 4 + size_t(c)];
  };

  // 2. One curve per distinct edge. Inner points computed from either side
  // differ by rounding; a looser tolerance relative to the edge's length still
  // tells apart two different edges between the same corners.
  std::vector<Curve> curves;
  std::unordered_map<uint64_t, std::vector<uint32_t>> by_corners;
  std::vector<uint32_t> refs(count * 4);
  auto inner_tol = [&](const glm::vec3* q) { return std::max(tol, 1e-3f * glm::length(q[3] - q[0])); };
  auto find_or_add = [&](uint32_t s, uint32_t e, const glm::vec3* q, bool add, size_t owner = 0,
                         int owner_edge = 0) -> uint32_t {
    const float t = inner_tol(q);
    auto& list = by_corners[pair_key(s, e)];
    for (uint32_t id : list) {
      int how = same_curve(curves[id], s, e, q, t);
      if (how) return (id << 1) | (how == 2 ? 1u : 0u);
    }
    if (!add) return MP_NO_CURVE;
    Curve c;
    for (int k = 0; k < 4; ++k) c.p[k] = q[k];
    c.start = s, c.end = e;
    c.owner = owner, c.owner_edge = owner_edge;
    curves.push_back(c);
    list.push_back(uint32_t(curves.size() - 1));
    return uint32_t(curves.size() - 1) << 1;
  };
  for (size_t p = first; p < buffer.size(); ++p)
    for (int e = 0; e < 4; ++e) {
      glm::vec3 q[4];
      for (int k = 0; k < 4; ++k) q[k] = glm::vec3(point(p, kEdgePoints[e][k]));
      uint32_t ref = find_or_add(rep_of(p, kEdgePoints[e][0]), rep_of(p, kEdgePoints[e][3]), q, true, p, e);
      ++curves[ref >> 1].users;
      refs[(p - first) * 4 + size_t(e)] = ref;
    }

  // 3. Edges nobody else shares may face two half-length edges: the curve's
  // middle is a corner of the surface and both halves are existing curves.
  std::unordered_map<uint32_t, std::vector<uint32_t>> neighbours;  // corner -> corners it has edges to
  for (const Curve& c : curves) {
    neighbours[c.start].push_back(c.end);
    neighbours[c.end].push_back(c.start);
  }
  std::vector<Transition> transitions;
  for (size_t p = first; p < buffer.size(); ++p)
    for (int e = 0; e < 4; ++e) {
      uint32_t& ref = refs[(p - first) * 4 + size_t(e)];
      uint32_t half_refs[2] = {ref, MP_NO_CURVE};
      const Curve& c = curves[ref >> 1];
      if (c.users == 1 && c.start != c.end) {
        glm::vec3 q[4], a[4], b[4];
        for (int k = 0; k < 4; ++k) q[k] = glm::vec3(point(p, kEdgePoints[e][k]));
        const uint32_t s = rep_of(p, kEdgePoints[e][0]), t = rep_of(p, kEdgePoints[e][3]);
        halve(q, a, b);
        const float near = inner_tol(q);
        for (uint32_t m : neighbours[s]) {
          if (m == t || m == s || max_distance(welder.rep(m), a[3]) > near) continue;
          a[3] = b[0] = welder.rep(m);
          uint32_t ra = find_or_add(s, m, a, false), rb = find_or_add(m, t, b, false);
          if (ra != MP_NO_CURVE && rb != MP_NO_CURVE) {
            half_refs[0] = ra, half_refs[1] = rb;
            transitions.push_back({p, e, m});
            break;
          }
        }
      }
      buffer.edges[p * MP_EDGE_REFS + 2 * size_t(e)] = half_refs[0];
      buffer.edges[p * MP_EDGE_REFS + 2 * size_t(e) + 1] = half_refs[1];
    }

  share_corner_uvs(buffer, first, corner_rep, transitions);

  // 4. Normal cubics: end points from one normal per welded corner (the
  // first patch's), inner control points so the cubic passes through the
  // owner's normal at t = 1/3 and 2/3.
  const glm::vec4* pts = buffer.points.data();
  const uint* info = reinterpret_cast<const uint*>(buffer.info.data());
  auto normal_at = [&](size_t p, int e, float t) {
    const float u = e == 0 || e == 2 ? t : e == 1 ? 1.0f : 0.0f;
    const float v = e == 1 || e == 3 ? t : e == 2 ? 1.0f : 0.0f;
    const glm::vec4* cp = pts + p * MP_PATCH_POINTS;
    float3 P, du, dv;
    mp_eval_patch(cp, info[4 * p], u, v, &P, &du, &dv);
    const MpPlacement none = mp_placement_none();
    return glm::vec3(mp_patch_normal(cp, info[4 * p], u, v, du, dv, &none));
  };
  std::unordered_map<uint32_t, glm::vec3> corner_normal;
  for (size_t p = first; p < buffer.size(); ++p)
    for (int e = 0; e < 4; ++e) corner_normal.emplace(rep_of(p, kEdgePoints[e][0]), normal_at(p, e, 0.0f));
  buffer.curves.reserve(buffer.curves.size() + curves.size() * MP_CURVE_FLOAT4S);
  const uint32_t base = uint32_t(buffer.curves.size() / MP_CURVE_FLOAT4S);
  for (const Curve& c : curves) {
    for (int k = 0; k < 4; ++k) buffer.curves.emplace_back(c.p[k], 0.0f);
    glm::vec3 b0 = corner_normal[c.start], b3 = corner_normal[c.end];
    if (glm::dot(b0, normal_at(c.owner, c.owner_edge, 0.0f)) < 0.0f) b0 = -b0;
    if (glm::dot(b3, normal_at(c.owner, c.owner_edge, 1.0f)) < 0.0f) b3 = -b3;
    const glm::vec3 r1 = 27.0f * normal_at(c.owner, c.owner_edge, 1.0f / 3.0f) - 8.0f * b0 - b3;
    const glm::vec3 r2 = 27.0f * normal_at(c.owner, c.owner_edge, 2.0f / 3.0f) - b0 - 8.0f * b3;
    const glm::vec3 n[4] = {b0, (2.0f * r1 - r2) / 18.0f, (2.0f * r2 - r1) / 18.0f, b3};
    for (int k = 0; k < 4; ++k) buffer.curves.emplace_back(n[k], 0.0f);
  }
  for (size_t p = first; p < buffer.size(); ++p)
    for (int r = 0; r < MP_EDGE_REFS; ++r) {
      uint32_t& ref = buffer.edges[p * MP_EDGE_REFS + size_t(r)];
      if (ref != MP_NO_CURVE) ref += base << 1;
    }
}

}  // namespace mp
