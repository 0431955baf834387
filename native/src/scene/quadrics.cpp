#include "scene/quadrics.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "micropoly/error.h"

namespace mp {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Cubic = std::array<glm::dvec3, 4>;  // one Bezier segment of the profile

// (cos, sin) of an angle in degrees, exact at multiples of 90 and the same
// for angles a whole turn apart, so seams and poles meet bit for bit.
glm::dvec2 unit(double degrees) {
  double d = std::fmod(degrees, 360.0);
  if (d < 0.0) d += 360.0;
  if (d == 0.0) return {1.0, 0.0};
  if (d == 90.0) return {0.0, 1.0};
  if (d == 180.0) return {-1.0, 0.0};
  if (d == 270.0) return {0.0, -1.0};
  const double r = d * kPi / 180.0;
  return {std::cos(r), std::sin(r)};
}

// Pieces of at most `max_arc` degrees covering an angle.
int pieces(double degrees, double max_arc) {
  return std::max(1, int(std::ceil(std::fabs(degrees) / max_arc - 1e-9)));
}

// Tangent length of a cubic arc of `degrees` on the unit circle.
double arc_k(double degrees) { return 4.0 / 3.0 * std::tan(degrees * kPi / 180.0 / 4.0); }

Cubic line(const glm::dvec3& a, const glm::dvec3& b) {
  return {a, a + (b - a) / 3.0, a + 2.0 * (b - a) / 3.0, b};
}

// The arc of radius r about (rho, 0, z) in the xz-plane from phi0 to phi1
// degrees, as cubic segments; boundary points computed once for both sides.
std::vector<Cubic> arc(double rho, double z, double r, double phi0, double phi1, double max_arc) {
  const int n = pieces(phi1 - phi0, max_arc);
  auto point = [&](const glm::dvec2& e) { return glm::dvec3(rho + r * e.x, 0.0, z + r * e.y); };
  std::vector<Cubic> out;
  for (int i = 0; i < n; ++i) {
    const std::array<glm::dvec2, 4> c =
        unit_arc(phi0 + (phi1 - phi0) * i / n, phi0 + (phi1 - phi0) * (i + 1) / n);
    out.push_back({point(c[0]), point(c[1]), point(c[2]), point(c[3])});
  }
  return out;
}

// The profile swept about z from 0 to `theta_max` degrees: one net per
// sweep span and profile segment, u along the sweep.
std::vector<glm::vec3> sweep(const std::vector<Cubic>& profile, double theta_max, double max_arc) {
  const int n = pieces(theta_max, max_arc);
  const double k = arc_k(theta_max / n);
  // R(e) q, and its derivative direction J R(e) q (linear in q).
  auto rotate = [](const glm::dvec2& e, const glm::dvec3& q) {
    return glm::dvec3(q.x * e.x - q.y * e.y, q.x * e.y + q.y * e.x, q.z);
  };
  auto turn = [](const glm::dvec2& e, const glm::dvec3& q) {
    return glm::dvec3(-(q.x * e.y + q.y * e.x), q.x * e.x - q.y * e.y, 0.0);
  };
  // -0 and +0 are the same point but not the same bits.
  auto stored = [](const glm::dvec3& p) { return glm::vec3(p) + glm::vec3(0.0f); };
  std::vector<glm::vec3> nets;
  nets.reserve(size_t(n) * profile.size() * 16);
  for (int i = 0; i < n; ++i) {
    const glm::dvec2 a = unit(theta_max * i / n), b = unit(theta_max * (i + 1) / n);
    for (const Cubic& c : profile)
      for (int row = 0; row < 4; ++row) {
        const glm::dvec3& q = c[size_t(row)];
        nets.push_back(stored(rotate(a, q)));
        nets.push_back(stored(rotate(a, q) + k * turn(a, q)));
        nets.push_back(stored(rotate(b, q) - k * turn(b, q)));
        nets.push_back(stored(rotate(b, q)));
      }
  }
  // The loop wrote row by row within each net: nets are 16 consecutive points.
  return nets;
}

double asin_degrees(double x) { return std::asin(std::clamp(x, -1.0, 1.0)) * 180.0 / kPi; }

}  // namespace

std::array<glm::dvec2, 4> unit_arc(double from, double to) {
  const double k = arc_k(to - from);
  const glm::dvec2 e0 = unit(from), e1 = unit(to);
  return {e0, e0 + k * glm::dvec2(-e0.y, e0.x), e1 - k * glm::dvec2(-e1.y, e1.x), e1};
}

bool quadric_kind(const std::string& request, QuadricKind* kind) {
  static const std::pair<const char*, QuadricKind> kNames[] = {
      {"Sphere", QuadricKind::Sphere},         {"Cylinder", QuadricKind::Cylinder},
      {"Cone", QuadricKind::Cone},             {"Disk", QuadricKind::Disk},
      {"Paraboloid", QuadricKind::Paraboloid}, {"Hyperboloid", QuadricKind::Hyperboloid},
      {"Torus", QuadricKind::Torus}};
  for (const auto& [name, k] : kNames)
    if (request == name) {
      *kind = k;
      return true;
    }
  return false;
}

size_t quadric_arg_count(QuadricKind kind) {
  switch (kind) {
    case QuadricKind::Cone:
    case QuadricKind::Disk:
      return 3;
    case QuadricKind::Hyperboloid:
      return 7;
    case QuadricKind::Torus:
      return 5;
    default:
      return 4;
  }
}

std::vector<glm::vec3> quadric_patches(QuadricKind kind, const std::vector<double>& args, double max_arc) {
  if (!(max_arc > 0.0 && max_arc <= 90.0)) throw Error("arcs must be of 0 to 90 degrees");
  if (args.size() != quadric_arg_count(kind))
    throw Error("expected " + std::to_string(quadric_arg_count(kind)) + " numbers, found " +
                std::to_string(args.size()));
  for (double v : args)
    if (!std::isfinite(v) || std::fabs(v) > 1e30) throw Error("a number is out of range (at most 1e30)");
  // A sweep past a whole turn would cover the surface twice.
  const double theta = std::clamp(args.back(), -360.0, 360.0);
  if (theta == 0.0) return {};
  std::vector<Cubic> profile;
  switch (kind) {
    case QuadricKind::Sphere: {
      const double r = args[0], zmin = args[1], zmax = args[2];
      if (r == 0.0) return {};
      // RI: phimin = zmin > -radius ? asin(zmin / radius) : -90 deg, alike for phimax.
      const double phi0 = zmin > -r ? asin_degrees(zmin / r) : -90.0;
      const double phi1 = zmax < r ? asin_degrees(zmax / r) : 90.0;
      if (phi0 == phi1) return {};
      profile = arc(0.0, 0.0, r, phi0, phi1, max_arc);
      break;
    }
    case QuadricKind::Cylinder: {
      const double r = args[0], zmin = args[1], zmax = args[2];
      if (r == 0.0 || zmin == zmax) return {};
      profile = {line({r, 0.0, zmin}, {r, 0.0, zmax})};
      break;
    }
    case QuadricKind::Cone: {
      const double h = args[0], r = args[1];
      if (r == 0.0) return {};
      profile = {line({r, 0.0, 0.0}, {0.0, 0.0, h})};
      break;
    }
    case QuadricKind::Disk: {
      const double h = args[0], r = args[1];
      if (r == 0.0) return {};
      profile = {line({r, 0.0, h}, {0.0, 0.0, h})};
      break;
    }
    case QuadricKind::Paraboloid: {
      // z = zmax (rho / rmax)^2 for z from zmin to zmax: a quadratic in rho,
      // so one cubic segment (the quadratic's degree elevation) is exact.
      const double rmax = args[0], zmin = args[1], zmax = args[2];
      if (zmax == 0.0) throw Error("zmax must not be 0");
      if (zmin / zmax < 0.0) throw Error("zmin and zmax must not lie on both sides of 0");
      if (rmax == 0.0 || zmin == zmax) return {};
      const double rho0 = rmax * std::sqrt(zmin / zmax), rho1 = rmax;
      const glm::dvec3 q0(rho0, 0.0, zmin), q2(rho1, 0.0, zmax);
      const glm::dvec3 q1(0.5 * (rho0 + rho1), 0.0, zmax / (rmax * rmax) * rho0 * rho1);
      profile = {{q0, (q0 + 2.0 * q1) / 3.0, (2.0 * q1 + q2) / 3.0, q2}};
      break;
    }
    case QuadricKind::Hyperboloid: {
      const glm::dvec3 p1(args[0], args[1], args[2]), p2(args[3], args[4], args[5]);
      if (p1 == p2) return {};
      profile = {line(p1, p2)};
      break;
    }
    case QuadricKind::Torus: {
      const double major = args[0], minor = args[1];
      const double phi0 = args[2], phi1 = phi0 + std::clamp(args[3] - args[2], -360.0, 360.0);
      if (minor == 0.0 || phi0 == phi1) return {};
      profile = arc(major, 0.0, minor, phi0, phi1, max_arc);
      break;
    }
  }
  return sweep(profile, theta, max_arc);
}

}  // namespace mp
