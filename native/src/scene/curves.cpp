#include "scene/curves.h"

#include <algorithm>
#include <array>
#include <cmath>

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

// Adds the tube around one curve's Bezier segments (centre line and radius,
// each segment starting where the last ended) to `out`.
void tube(const std::vector<CurveSegment>& segs, std::vector<glm::vec3>& out) {
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
  for (size_t i = 0; i < n; ++i) {
    // Rows 0 and 1 take the segment's first joint's frame, rows 2 and 3 its
    // last's: the rings at the joints are exact and shared with the
    // neighbouring segments.
    const Frame* f[4] = {&frames[i], &frames[i], &frames[i + 1], &frames[i + 1]};
    for (int q = 0; q < 4; ++q) {
      const std::array<glm::dvec2, 4> dirs = unit_arc(90.0 * q, 90.0 * (q + 1));  // a quarter turn
      for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) {
          const glm::dvec3 d = dirs[col].x * f[row]->n + dirs[col].y * f[row]->m;
          out.push_back(glm::vec3(segs[i].p[row] + segs[i].r[row] * d) + glm::vec3(0.0f));
        }
    }
  }
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

void add_tube(const std::vector<CurveSegment>& segs, std::vector<glm::vec3>& out) {
  if (!segs.empty()) tube(segs, out);
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
  BezierPatches set;
  set.name = curves.name;
  set.material = curves.material;
  set.object_to_world = curves.object_to_world;
  set.double_sided = true;
  set.visible_camera = curves.visible_camera;
  set.cast_shadows = curves.cast_shadows;
  set.info = curves.info;
  size_t skipped = 0;
  std::vector<glm::dvec3> k;
  std::vector<double> r;
  std::vector<CurveSegment> segs;
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
    tube(segs, set.control_points);
  }
  if (!set.control_points.empty()) scene.bezier_patches.push_back(std::move(set));
  return skipped;
}

}  // namespace mp
