#include "scene/nurbs.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "micropoly/error.h"

namespace mp {
namespace {

// The span k with knot[k] <= t < knot[k + 1] among the domain's spans
// [order - 1, n - 1]; the last span holds t = its end.
int find_span(const std::vector<double>& knot, int n, int order, double t) {
  int lo = order - 1, hi = n - 1;
  if (t >= knot[size_t(hi + 1)]) {
    while (hi > lo && knot[size_t(hi)] == knot[size_t(hi + 1)]) --hi;
    return hi;
  }
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (knot[size_t(mid)] <= t) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

// The `order` basis functions that are not zero at t in span k
// (N[k - order + 1 + j], j < order), by the triangular recurrence.
void basis(const std::vector<double>& knot, int k, int order, double t, double* out) {
  double left[16], right[16];
  out[0] = 1.0;
  for (int j = 1; j < order; ++j) {
    left[j] = t - knot[size_t(k + 1 - j)];
    right[j] = knot[size_t(k + j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double d = right[r + 1] + left[j - r];
      const double temp = d != 0.0 ? out[r] / d : 0.0;
      out[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    out[j] = saved;
  }
}

// The parameters where the rendered range [lo, hi] changes span: lo, the
// distinct knots inside, hi.
std::vector<double> breaks(const std::vector<double>& knot, double lo, double hi) {
  std::vector<double> b{lo};
  for (double k : knot)
    if (k > lo && k < hi && k != b.back()) b.push_back(k);
  b.push_back(hi);
  return b;
}

// Inverse of the cubic Bernstein values at 0, 1/3, 2/3, 1: maps four
// samples of a cubic to its Bezier points.
struct Interpolation {
  double m[4][4];
  Interpolation() {
    double a[4][8] = {};
    for (int i = 0; i < 4; ++i) {
      const double t = i / 3.0, s = 1.0 - t;
      a[i][0] = s * s * s, a[i][1] = 3 * s * s * t, a[i][2] = 3 * s * t * t, a[i][3] = t * t * t;
      a[i][4 + i] = 1.0;
    }
    for (int c = 0; c < 4; ++c) {  // Gauss-Jordan; the matrix is well conditioned
      int p = c;
      for (int r = c + 1; r < 4; ++r)
        if (std::fabs(a[r][c]) > std::fabs(a[p][c])) p = r;
      for (int k = 0; k < 8; ++k) std::swap(a[c][k], a[p][k]);
      const double d = a[c][c];
      for (int k = 0; k < 8; ++k) a[c][k] /= d;
      for (int r = 0; r < 4; ++r)
        if (r != c) {
          const double f = a[r][c];
          for (int k = 0; k < 8; ++k) a[r][k] -= f * a[c][k];
        }
    }
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m[r][c] = a[r][4 + c];
    // Exact ends: the border rows take the border samples as they are.
    for (int c = 0; c < 4; ++c) m[0][c] = c == 0, m[3][c] = c == 3;
  }
};

// Where piece k of `pieces` along span a starts: the span's own ends
// exactly, so neighbouring spans' pieces meet at the same parameter.
double cut(const std::vector<double>& b, size_t a, int k, int pieces) {
  if (k == 0) return b[a];
  if (k == pieces) return b[a + 1];
  return b[a] + (b[a + 1] - b[a]) * k / pieces;
}

glm::dvec3 bezier_at(const glm::dvec3 net[16], double u, double v) {
  auto b = [](double t, double* w) {
    const double s = 1.0 - t;
    w[0] = s * s * s, w[1] = 3 * s * s * t, w[2] = 3 * s * t * t, w[3] = t * t * t;
  };
  double bu[4], bv[4];
  b(u, bu), b(v, bv);
  glm::dvec3 p(0.0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) p += bu[i] * bv[j] * net[4 * j + i];
  return p;
}

// The interpolating net of the surface over [u0, u1] x [v0, v1].
void piece_net(const NurbsSurface& s, const Interpolation& ip, double u0, double u1, double v0, double v1,
               glm::dvec3 net[16]) {
  glm::dvec3 samples[4][4], rows[4][4];
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const double u = i == 3 ? u1 : u0 + (u1 - u0) * (i / 3.0);
      const double v = j == 3 ? v1 : v0 + (v1 - v0) * (j / 3.0);
      samples[j][i] = nurbs_point(s, u, v);
    }
  for (int j = 0; j < 4; ++j)
    for (int r = 0; r < 4; ++r) {
      rows[j][r] = glm::dvec3(0.0);
      for (int i = 0; i < 4; ++i) rows[j][r] += ip.m[r][i] * samples[j][i];
    }
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      glm::dvec3 p(0.0);
      for (int j = 0; j < 4; ++j) p += ip.m[r][j] * rows[j][c];
      net[4 * r + c] = p;
    }
}

}  // namespace

void check_nurbs(const NurbsSurface& s) {
  auto dir = [](const char* name, int n, int order, const std::vector<double>& knot, double lo, double hi) {
    if (order < 1 || order > 16) throw Error(std::string(name) + "order " + std::to_string(order) + " is not 1 to 16");
    if (n < order)
      throw Error(std::string("n") + name + " = " + std::to_string(n) + " is less than the order " + std::to_string(order));
    if (knot.size() != size_t(n + order))
      throw Error(std::string(name) + "knot has " + std::to_string(knot.size()) + " values; n" + name + " + " + name +
                  "order = " + std::to_string(n + order));
    for (size_t k = 0; k < knot.size(); ++k) {
      if (!std::isfinite(knot[k])) throw Error(std::string(name) + "knot value " + std::to_string(k) + " is not finite");
      if (k > 0 && knot[k] < knot[k - 1]) throw Error(std::string(name) + "knot decreases at value " + std::to_string(k));
    }
    const double a = knot[size_t(order - 1)], b = knot[size_t(n)];
    if (!(a < b)) throw Error(std::string(name) + "knot leaves no parameter range to render");
    if (!(lo >= a && hi <= b && lo < hi))
      throw Error(std::string(name) + "min " + std::to_string(lo) + " to " + name + "max " + std::to_string(hi) +
                  " is not within the knots' range " + std::to_string(a) + " to " + std::to_string(b));
  };
  dir("u", s.nu, s.uorder, s.uknot, s.umin, s.umax);
  dir("v", s.nv, s.vorder, s.vknot, s.vmin, s.vmax);
  if (s.points.size() != size_t(s.nu) * size_t(s.nv))
    throw Error("\"P\" has " + std::to_string(s.points.size()) + " points, nu * nv = " +
                std::to_string(size_t(s.nu) * size_t(s.nv)));
  for (const glm::dvec4& p : s.points)
    if (!(p.w > 0.0) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.w))
      throw Error("a control point is not finite or its weight is not positive");
}

glm::dvec3 nurbs_point(const NurbsSurface& s, double u, double v) {
  const int ku = find_span(s.uknot, s.nu, s.uorder, u), kv = find_span(s.vknot, s.nv, s.vorder, v);
  double bu[16], bv[16];
  basis(s.uknot, ku, s.uorder, u, bu);
  basis(s.vknot, kv, s.vorder, v, bv);
  glm::dvec4 h(0.0);
  for (int j = 0; j < s.vorder; ++j) {
    glm::dvec4 row(0.0);
    for (int i = 0; i < s.uorder; ++i)
      row += bu[i] * s.points[size_t(ku - s.uorder + 1 + i) + size_t(s.nu) * size_t(kv - s.vorder + 1 + j)];
    h += bv[j] * row;
  }
  return glm::dvec3(h) / h.w;
}

std::vector<glm::vec3> nurbs_patches(const NurbsSurface& s) {
  check_nurbs(s);
  static const Interpolation ip;
  const std::vector<double> bu = breaks(s.uknot, s.umin, s.umax), bv = breaks(s.vknot, s.vmin, s.vmax);
  // The surface's size: the control hull's box diagonal.
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec4& p : s.points) lo = glm::min(lo, glm::dvec3(p) / p.w), hi = glm::max(hi, glm::dvec3(p) / p.w);
  const double tolerance = kNurbsTolerance * std::max(glm::length(hi - lo), 1e-300);
  // The least number of halvings, the same for every span (neighbours
  // then share their borders' parameters), that meets the tolerance.
  const bool exact = s.uorder <= 4 && s.vorder <= 4 &&
                     std::all_of(s.points.begin(), s.points.end(), [&](const glm::dvec4& p) { return p.w == s.points[0].w; });
  int halvings = 0;
  for (; !exact && halvings < kMaxNurbsHalvings; ++halvings) {
    const int pieces = 1 << halvings;
    double worst = 0.0;
    for (size_t a = 0; a + 1 < bu.size(); ++a)
      for (size_t b = 0; b + 1 < bv.size(); ++b)
        for (int pi = 0; pi < pieces; ++pi)
          for (int pj = 0; pj < pieces; ++pj) {
            const double u0 = cut(bu, a, pi, pieces), u1 = cut(bu, a, pi + 1, pieces);
            const double v0 = cut(bv, b, pj, pieces), v1 = cut(bv, b, pj + 1, pieces);
            glm::dvec3 net[16];
            piece_net(s, ip, u0, u1, v0, v1, net);
            for (double tu : {1.0 / 6.0, 0.5, 5.0 / 6.0})
              for (double tv : {1.0 / 6.0, 0.5, 5.0 / 6.0})
                worst = std::max(worst, glm::length(bezier_at(net, tu, tv) -
                                                    nurbs_point(s, u0 + (u1 - u0) * tu, v0 + (v1 - v0) * tv)));
          }
    if (worst <= tolerance) break;
  }
  const int pieces = 1 << halvings;
  std::vector<glm::vec3> out;
  out.reserve((bu.size() - 1) * (bv.size() - 1) * size_t(pieces * pieces) * 16);
  for (size_t b = 0; b + 1 < bv.size(); ++b)
    for (int pj = 0; pj < pieces; ++pj)
      for (size_t a = 0; a + 1 < bu.size(); ++a)
        for (int pi = 0; pi < pieces; ++pi) {
          const double u0 = cut(bu, a, pi, pieces), u1 = cut(bu, a, pi + 1, pieces);
          const double v0 = cut(bv, b, pj, pieces), v1 = cut(bv, b, pj + 1, pieces);
          glm::dvec3 net[16];
          piece_net(s, ip, u0, u1, v0, v1, net);
          for (const glm::dvec3& p : net) out.emplace_back(p);
        }
  return out;
}

}  // namespace mp
