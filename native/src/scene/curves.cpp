#include "scene/curves.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "geometry/mp_patch.h"
#include "micropoly/error.h"
#include "scene/quadrics.h"

namespace mp {
namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Any unit vector perpendicular to `t` (unit).
glm::dvec3 perpendicular(const glm::dvec3& t) {
  const glm::dvec3 helper = std::fabs(t.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(t, helper));
}

struct Frame {
  glm::dvec3 n, m;  // the section's axes: n, and m = t x n
};

// The most a tube piece's centre line may turn (the angles between its
// control polygon's legs, a bound on the turning), and the most halvings
// that keep to it.
constexpr double kMaxTurnRadians = 0.5236;  // 30 degrees
constexpr int kMaxHalvings = 4;

double polygon_turn(const CurveSegment& s) {
  double turn = 0.0;
  for (int k = 0; k + 2 < 4; ++k) {
    const glm::dvec3 a = s.p[k + 1] - s.p[k], b = s.p[k + 2] - s.p[k + 1];
    const double la = glm::length(a), lb = glm::length(b);
    if (la > 0.0 && lb > 0.0) turn += std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
  }
  return turn;
}

// The segment's halves at t = 1/2 (de Casteljau), centre line and radius.
void halve(const CurveSegment& s, CurveSegment& a, CurveSegment& b) {
  auto split = [](const auto* p, auto* lo, auto* hi) {
    const auto p01 = 0.5 * (p[0] + p[1]), p12 = 0.5 * (p[1] + p[2]), p23 = 0.5 * (p[2] + p[3]);
    const auto q0 = 0.5 * (p01 + p12), q1 = 0.5 * (p12 + p23), m = 0.5 * (q0 + q1);
    lo[0] = p[0], lo[1] = p01, lo[2] = q0, lo[3] = m;
    hi[0] = m, hi[1] = q1, hi[2] = p23, hi[3] = p[3];
  };
  split(s.p, a.p, b.p);
  split(s.r, a.r, b.r);
}

// How many times to halve a segment: until each of its 2^k equal pieces
// turns by at most kMaxTurnRadians.
int halvings(const CurveSegment& s) {
  int k = 0;
  std::vector<CurveSegment> pieces{s}, next;
  while (k < kMaxHalvings && std::any_of(pieces.begin(), pieces.end(),
                                         [](const CurveSegment& p) { return polygon_turn(p) > kMaxTurnRadians; })) {
    next.clear();
    for (const CurveSegment& p : pieces) {
      CurveSegment a, b;
      halve(p, a, b);
      next.push_back(a), next.push_back(b);
    }
    pieces.swap(next);
    ++k;
  }
  return k;
}

// Appends `s` cut into 2^k equal pieces.
void cut(const CurveSegment& s, int k, std::vector<CurveSegment>& out) {
  if (k == 0) {
    out.push_back(s);
    return;
  }
  CurveSegment a, b;
  halve(s, a, b);
  cut(a, k - 1, out);
  cut(b, k - 1, out);
}

// Adds the tube around one curve's Bezier segments (centre line and radius,
// each segment starting where the last ended) to `out`, segment i cut into
// 2^levels[i] pieces first: a piece's rows follow its frame's rotation only
// to first order. A moving curve's steps take the shutter centre's levels,
// so every step has the same patches.
void tube(const std::vector<CurveSegment>& input, const std::vector<int>& levels, std::vector<glm::vec3>& out) {
  std::vector<CurveSegment> segs;
  for (size_t i = 0; i < input.size(); ++i) cut(input[i], levels[i], segs);
  const size_t n = segs.size();
  // A frame at each joint (n + 1), perpendicular to the curve's direction
  // there, carried along by projecting the last normal onto each new section
  // plane (parallel transport, so the tube does not twist).
  auto direction = [](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& fallback) {
    const glm::dvec3 d = b - a;
    return glm::length(d) > 0.0 ? d : fallback;
  };
  std::vector<Frame> frames(n + 1);
  glm::dvec3 normal(0.0);
  for (size_t j = 0; j <= n; ++j) {
    glm::dvec3 t(0.0);
    if (j < n) t += glm::normalize(direction(segs[j].p[0], segs[j].p[1], direction(segs[j].p[0], segs[j].p[3], {0, 0, 1})));
    if (j > 0)
      t += glm::normalize(direction(segs[j - 1].p[2], segs[j - 1].p[3], direction(segs[j - 1].p[0], segs[j - 1].p[3], {0, 0, 1})));
    const double len = glm::length(t);
    t = len > 0.0 ? t / len : glm::dvec3(0, 0, 1);
    glm::dvec3 p = j == 0 ? perpendicular(t) : normal - glm::dot(normal, t) * t;
    const double pl = glm::length(p);
    normal = pl > 1e-12 ? p / pl : perpendicular(t);
    frames[j] = {normal, glm::cross(t, normal)};
  }
  // The section's offset O(v) = r(v) d(v) turns with the frame as the
  // centre line bends; its Bezier rows are a cubic Hermite of the offsets
  // and their derivatives at the two joints, O' = r' d + r (w x d), where
  // w = C' x C'' / |C'|^2 is the rotation-minimising frame's angular
  // velocity. The rings at the joints are exact and shared with the
  // neighbouring segments; between them the tube keeps its radius to about
  // 1% for a segment that turns 90 degrees (rows that only blended the two
  // rings would pinch it to cos(45) there).
  auto spin = [](const glm::dvec3& d1, const glm::dvec3& d2) {
    const double l2 = glm::dot(d1, d1);
    return l2 > 0.0 ? glm::cross(d1, d2) / l2 : glm::dvec3(0.0);
  };
  for (size_t i = 0; i < n; ++i) {
    const CurveSegment& sg = segs[i];
    const glm::dvec3 w0 = spin(3.0 * (sg.p[1] - sg.p[0]), 6.0 * (sg.p[2] - 2.0 * sg.p[1] + sg.p[0]));
    const glm::dvec3 w1 = spin(3.0 * (sg.p[3] - sg.p[2]), 6.0 * (sg.p[3] - 2.0 * sg.p[2] + sg.p[1]));
    for (int q = 0; q < 4; ++q) {
      const std::array<glm::dvec2, 4> dirs = unit_arc(90.0 * q, 90.0 * (q + 1));  // a quarter turn
      for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) {
          const Frame& f = frames[row < 2 ? i : i + 1];
          const glm::dvec3 d = dirs[col].x * f.n + dirs[col].y * f.m;
          glm::dvec3 o = sg.r[row] * d;
          if (row == 1) o += sg.r[0] / 3.0 * glm::cross(w0, d);
          if (row == 2) o -= sg.r[3] / 3.0 * glm::cross(w1, d);
          out.push_back(glm::vec3(sg.p[row] + o));
        }
    }
  }
}

// Appends to the set's UV layers the corner values of one curve's tube
// patches (as tube() emits them: segment i cut into 2^levels[i] pieces, four
// quarter-turn patches each, v along the curve): the values at the curve's
// keys, from point `first` on, blended linearly along each segment.
void tube_layers(const CurveSet& curves, size_t first, const std::vector<int>& levels, BezierPatches& set) {
  for (size_t l = 0; l < curves.point_layers.size(); ++l) {
    const std::vector<glm::vec2>& values = curves.point_layers[l];
    std::vector<glm::vec2>& out = set.uv_layers[l];
    for (size_t i = 0; i < levels.size(); ++i) {
      const int pieces = 1 << levels[i];
      for (int j = 0; j < pieces; ++j) {
        const glm::vec2 lo = glm::mix(values[first + i], values[first + i + 1], float(j) / float(pieces));
        const glm::vec2 hi = glm::mix(values[first + i], values[first + i + 1], float(j + 1) / float(pieces));
        for (int q = 0; q < kTubePatchesPerSegment; ++q) out.insert(out.end(), {lo, lo, hi, hi});
      }
    }
  }
}

// Appends to the set's UV layers the corner values of one curve's ribbon
// patches, one a segment (u across, v along): as tube_layers without cuts.
void ribbon_layers(const CurveSet& curves, size_t first, size_t segments, BezierPatches& set) {
  for (size_t l = 0; l < curves.point_layers.size(); ++l) {
    const std::vector<glm::vec2>& values = curves.point_layers[l];
    std::vector<glm::vec2>& out = set.uv_layers[l];
    for (size_t i = 0; i < segments; ++i) {
      const glm::vec2 lo = values[first + i], hi = values[first + i + 1];
      out.insert(out.end(), {lo, lo, hi, hi});
    }
  }
}

// The patch set that holds a curve set's tubes, without patches yet.
BezierPatches tube_set(const CurveSet& curves) {
  BezierPatches set;
  set.name = curves.name;
  set.material = curves.material;
  set.object_to_world = curves.object_to_world;
  set.double_sided = true;
  set.visible_camera = curves.visible_camera;
  set.cast_shadows = curves.cast_shadows;
  set.info = curves.info;
  set.round_u = !curves.ribbons;
  set.ribbons = curves.ribbons;
  set.uv_layers.resize(curves.point_layers.size());
  return set;
}

}  // namespace

void catmull_rom_segments(const std::vector<glm::dvec3>& k, const std::vector<double>& r,
                          std::vector<CurveSegment>& segs) {
  segs.clear();
  const long n = long(k.size());
  auto key = [&](long i) { return k[size_t(std::clamp<long>(i, 0, n - 1))]; };
  auto rad = [&](long i) { return r[size_t(std::clamp<long>(i, 0, n - 1))]; };
  // Catmull-Rom to Bezier: the inner points a sixth of the neighbours' chord away.
  for (long a = 0; a + 1 < n; ++a)
    segs.push_back({{key(a), key(a) + (key(a + 1) - key(a - 1)) / 6.0, key(a + 1) - (key(a + 2) - key(a)) / 6.0, key(a + 1)},
                    {rad(a), rad(a) + (rad(a + 1) - rad(a - 1)) / 6.0, rad(a + 1) - (rad(a + 2) - rad(a)) / 6.0, rad(a + 1)}});
}

void add_ribbon(const CurveSegment& s, std::vector<glm::vec3>& out) {
  // A radius control value may dip below zero near a tip (Catmull-Rom's
  // inner values); the offsets' length takes its size.
  for (int j = 0; j < 4; ++j) {
    const double r = std::fabs(s.r[j]);
    out.push_back(glm::vec3(s.p[j]));
    out.push_back(glm::vec3(s.p[j] + glm::dvec3(r, 0.0, 0.0)));
    out.push_back(glm::vec3(s.p[j] + glm::dvec3(0.0, r, 0.0)));
    out.push_back(glm::vec3(s.p[j] + glm::dvec3(0.0, 0.0, r)));
  }
}

void add_tube(const std::vector<CurveSegment>& segs, std::vector<glm::vec3>& out) {
  std::vector<int> levels(segs.size());
  for (size_t i = 0; i < segs.size(); ++i) levels[i] = halvings(segs[i]);
  if (!segs.empty()) tube(segs, levels, out);
}

size_t add_curves(Scene& scene, const CurveSet& curves) {
  const std::vector<int>& off = curves.offsets;
  if (curves.radii.size() != curves.points.size())
    throw Error("curves '" + curves.name + "': " + std::to_string(curves.points.size()) + " points but " +
                std::to_string(curves.radii.size()) + " radii");
  if (off.empty() || off.front() != 0 || size_t(off.back()) != curves.points.size())
    throw Error("curves '" + curves.name + "': the offsets must run from 0 to the number of points");
  for (size_t c = 0; c + 1 < off.size(); ++c)
    if (off[c + 1] < off[c]) throw Error("curves '" + curves.name + "': the offsets must not decrease");
  for (size_t step = 0; step < curves.motion_points.size(); ++step) {
    if (curves.motion_points[step].size() != curves.points.size())
      throw Error("curves '" + curves.name + "': motion step " + std::to_string(step) + " has " +
                  std::to_string(curves.motion_points[step].size()) + " points, not " +
                  std::to_string(curves.points.size()));
    for (const glm::vec3& v : curves.motion_points[step])
      if (!finite(v)) throw Error("curves '" + curves.name + "': a motion point is not finite");
  }
  if (curves.point_layers.size() > MP_MAX_UV_LAYERS)
    throw Error("curves '" + curves.name + "': " + std::to_string(curves.point_layers.size()) +
                " UV layers; at most " + std::to_string(MP_MAX_UV_LAYERS) + " are supported");
  for (const std::vector<glm::vec2>& layer : curves.point_layers) {
    if (layer.size() != curves.points.size())
      throw Error("curves '" + curves.name + "': a UV layer has " + std::to_string(layer.size()) +
                  " values; it needs one per point (" + std::to_string(curves.points.size()) + ")");
    for (const glm::vec2& v : layer)
      if (!std::isfinite(v.x) || !std::isfinite(v.y))
        throw Error("curves '" + curves.name + "': a UV layer value is not finite");
  }
  BezierPatches set = tube_set(curves);
  set.motion_object_to_world = curves.motion_object_to_world;
  set.motion_control_points.resize(curves.motion_points.size());
  size_t skipped = 0;
  std::vector<glm::dvec3> k;
  std::vector<double> r;
  std::vector<CurveSegment> segs;
  std::vector<int> levels;
  for (size_t c = 0; c + 1 < off.size(); ++c) {
    k.clear(), r.clear();
    bool ok = off[c + 1] - off[c] >= 2;
    for (int p = off[c]; ok && p < off[c + 1]; ++p) {
      const glm::vec3 v = curves.points[size_t(p)];
      const float w = curves.radii[size_t(p)];
      ok = finite(v) && std::isfinite(w) && w >= 0.0f;
      k.emplace_back(v);
      r.push_back(w);
    }
    if (!ok) {
      ++skipped;
      continue;
    }
    catmull_rom_segments(k, r, segs);
    if (curves.ribbons) {
      for (const CurveSegment& sg : segs) add_ribbon(sg, set.control_points);
      ribbon_layers(curves, size_t(off[c]), segs.size(), set);
      for (size_t step = 0; step < curves.motion_points.size(); ++step) {
        for (int p = off[c]; p < off[c + 1]; ++p) k[size_t(p - off[c])] = curves.motion_points[step][size_t(p)];
        catmull_rom_segments(k, r, segs);
        for (const CurveSegment& sg : segs) add_ribbon(sg, set.motion_control_points[step]);
      }
      continue;
    }
    levels.resize(segs.size());
    for (size_t i = 0; i < segs.size(); ++i) levels[i] = halvings(segs[i]);
    tube(segs, levels, set.control_points);
    tube_layers(curves, size_t(off[c]), levels, set);
    // Each motion step's tube, cut as the shutter centre's is.
    for (size_t step = 0; step < curves.motion_points.size(); ++step) {
      for (int p = off[c]; p < off[c + 1]; ++p) k[size_t(p - off[c])] = curves.motion_points[step][size_t(p)];
      catmull_rom_segments(k, r, segs);
      tube(segs, levels, set.motion_control_points[step]);
    }
  }
  if (!set.control_points.empty()) scene.bezier_patches.push_back(std::move(set));
  return skipped;
}

void add_bezier_curves(Scene& scene, const CurveSet& meta, const std::vector<std::vector<CurveSegment>>& runs) {
  BezierPatches set = tube_set(meta);
  for (const std::vector<CurveSegment>& run : runs) {
    if (!meta.ribbons) add_tube(run, set.control_points);
    else
      for (const CurveSegment& sg : run) add_ribbon(sg, set.control_points);
  }
  if (!set.control_points.empty()) scene.bezier_patches.push_back(std::move(set));
}

}  // namespace mp
