// NURBS surfaces (RenderMan's NuPatch, RI spec 3.2 section 5.5) as bicubic
// Bezier nets, which the pipeline bounds, splits and dices as any Patch.
//
// The surface is evaluated exactly (Cox-de Boor basis functions, Piegl and
// Tiller, "The NURBS Book", A2.2; rational points divided by their weight)
// and each knot span of the rendered range [umin, umax] x [vmin, vmax] is
// replaced by the bicubic that interpolates it on a 4 x 4 grid of its
// parameters. A polynomial surface of degree 3 or less is a bicubic on each
// span, so the nets are exact there (to rounding); a rational surface or one
// of higher degree is approximated, every span cut into 2^k x 2^k pieces
// for the least k (at most kMaxNurbsHalvings) whose nets stay within
// kNurbsTolerance of the surface's size, measured between the grid's points.
// A net's border depends only on the samples along that border, and the
// pieces of neighbouring spans share their border's parameters, so the nets
// share bit-identical edges (the pipeline's crack-free dicing).
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace mp {

constexpr double kNurbsTolerance = 1e-4;
constexpr int kMaxNurbsHalvings = 4;

struct NurbsSurface {
  int nu = 0, uorder = 0, nv = 0, vorder = 0;
  std::vector<double> uknot, vknot;  // nu + uorder and nv + vorder values, not decreasing
  double umin = 0.0, umax = 1.0, vmin = 0.0, vmax = 1.0;
  std::vector<glm::dvec4> points;    // homogeneous (w x, w y, w z, w), u fastest: points[u + nu * v]
};

// Throws mp::Error saying what is wrong: counts, orders, knots, a range
// outside the knots' domain or a weight that is not positive.
void check_nurbs(const NurbsSurface& s);

// The surface at (u, v), within the knots' domain.
glm::dvec3 nurbs_point(const NurbsSurface& s, double u, double v);

// The Bezier nets (16 points each, u along each row, as Patch) of the
// surface over its rendered range. Checks the surface first.
std::vector<glm::vec3> nurbs_patches(const NurbsSurface& s);

}  // namespace mp
