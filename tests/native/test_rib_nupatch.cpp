// RIB NuPatch (scene/nurbs.h, rib/rib_nupatch.cpp): NURBS surfaces as Bezier
// nets. A uniform B-spline NuPatch against the same surface as a B-spline
// PatchMesh; a rational cylinder and sphere against their analytic radius,
// projected area and watertightness seen from inside; errors; round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "renderer_fixture.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene/nurbs.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

// The rational quadratic circle of radius r in the xy-plane (9 points,
// RenderMan's homogeneous "Pw" values, weights 1 and sqrt(1/2)).
std::vector<glm::dvec4> circle(double r, double z) {
  const double w = std::sqrt(0.5);
  std::vector<glm::dvec4> pts;
  const double xs[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1}, ys[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
  for (int i = 0; i < 9; ++i) {
    const double k = i % 2 ? w : 1.0;
    pts.emplace_back(k * r * xs[i], k * r * ys[i], k * z, k);
  }
  return pts;
}
const char* kCircleKnots = "[0 0 0 0.25 0.25 0.5 0.5 0.75 0.75 1 1 1]";

// A cylinder of radius 1 from z = -1 to 1: the circle swept along z (order 2).
std::string cylinder() {
  std::string pw;
  for (double z : {-1.0, 1.0})
    for (const glm::dvec4& p : circle(1.0, z))
      pw += num(p.x) + " " + num(p.y) + " " + num(p.z) + " " + num(p.w) + "  ";
  return std::string("NuPatch 9 3 ") + kCircleKnots + " 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [" + pw + "]";
}

// A unit sphere: the circle swept by a half circle of the same construction
// (5 points, the poles collapsed), rational in both directions.
std::string sphere() {
  const double w = std::sqrt(0.5);
  const double rz[5][3] = {{0, -1, 1}, {1, -1, w}, {1, 0, 1}, {1, 1, w}, {0, 1, 1}};  // radius, z, weight
  std::string pw;
  for (const auto& m : rz)
    for (const glm::dvec4& c : circle(1.0, 0.0)) {
      const double k = m[2] * c.w;  // the weights multiply
      pw += num(k * m[0] * c.x / c.w) + " " + num(k * m[0] * c.y / c.w) + " " + num(k * m[1]) + " " + num(k) + "  ";
    }
  return std::string("NuPatch 9 3 ") + kCircleKnots + " 0 1 5 3 [0 0 0 0.5 0.5 1 1 1] 0 1 \"Pw\" [" + pw + "]";
}

std::vector<glm::vec3> nets_of(const std::string& request) {
  const RibResult r = read_rib_string("WorldBegin\n" + request + "\nWorldEnd\n", "nu.rib");
  if (r.scene.bezier_patches.size() != 1) {
    ADD_FAILURE() << r.scene.bezier_patches.size() << " patch sets";
    return {};
  }
  return r.scene.bezier_patches[0].control_points;
}

glm::dvec3 net_point(const glm::vec3* net, double u, double v) {
  auto b = [](double t, double* w) {
    const double s = 1.0 - t;
    w[0] = s * s * s, w[1] = 3 * s * s * t, w[2] = 3 * s * t * t, w[3] = t * t * t;
  };
  double bu[4], bv[4];
  b(u, bu), b(v, bv);
  glm::dvec3 p(0.0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) p += bu[i] * bv[j] * glm::dvec3(net[4 * j + i]);
  return p;
}

TEST(RibNuPatch, RationalSurfacesStayWithinTheirTolerance) {
  // Exact evaluation first: the rational circle is a circle.
  NurbsSurface s;
  s.nu = 9, s.uorder = 3, s.nv = 2, s.vorder = 2;
  s.uknot = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
  s.vknot = {0, 0, 1, 1};
  for (double z : {-1.0, 1.0})
    for (const glm::dvec4& p : circle(1.0, z)) s.points.push_back(p);
  for (int k = 0; k <= 40; ++k) EXPECT_NEAR(glm::length(glm::dvec2(nurbs_point(s, k / 40.0, 0.3))), 1.0, 1e-12);
  // The nets: within the stated tolerance of the size (the hull's diagonal, 3.5).
  for (const std::string& request : {cylinder(), sphere()}) {
    const std::vector<glm::vec3> cps = nets_of(request);
    ASSERT_FALSE(cps.empty());
    const bool is_sphere = request == sphere();
    double worst = 0.0;
    for (size_t n = 0; n < cps.size() / 16; ++n)
      for (int a = 0; a <= 8; ++a)
        for (int b = 0; b <= 8; ++b) {
          const glm::dvec3 p = net_point(&cps[16 * n], a / 8.0, b / 8.0);
          worst = std::max(worst, std::fabs((is_sphere ? glm::length(p) : glm::length(glm::dvec2(p))) - 1.0));
        }
    EXPECT_LT(worst, kNurbsTolerance * 3.5) << request.substr(0, 20);
    EXPECT_GT(worst, 1e-9) << "rational surfaces are approximated";
  }
}

class RibNuPatchRender : public SharedRendererTest {
 protected:
  RenderResult render(const std::string& rib) { return renderer_->render(read_rib_string(rib, "nu.rib").scene); }
};

std::string ortho_frame(double s, const std::string& camera, const std::string& body) {
  return "Format 160 160 1\nPixelSamples 4 4\nProjection \"orthographic\"\nScreenWindow " + num(-s) + " " + num(s) +
         " " + num(-s) + " " + num(s) + "\nTranslate 0 0 5\n" + camera + "\nWorldBegin\nSurface \"constant\"\n" + body +
         "\nWorldEnd\n";
}

TEST_F(RibNuPatchRender, BSplineNuPatchIsTheBSplinePatchMesh) {
  // 5 x 5 control points of a wavy sheet, uniform cubic knots: the NuPatch
  // over its whole domain is the nonperiodic B-spline PatchMesh.
  std::string P;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i)
      P += num(i * 0.8 - 1.6) + " " + num(j * 0.8 - 1.6) + " " + num(0.4 * std::sin(1.3 * i + 0.7 * j)) + "  ";
  const RenderResult nu = render(ortho_frame(2.5, "Rotate 30 1 0 0",
                                             "NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 3 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" [" + P + "]"));
  const RenderResult mesh = render(ortho_frame(2.5, "Rotate 30 1 0 0",
                                               "Basis \"b-spline\" 1 \"b-spline\" 1\nPatchMesh \"bicubic\" 5 \"nonperiodic\" 5 "
                                               "\"nonperiodic\" \"P\" [" + P + "]"));
  double diff = 0.0;
  for (size_t i = 0; i < size_t(nu.width) * nu.height; ++i) diff += std::fabs(nu.rgba[4 * i + 3] - mesh.rgba[4 * i + 3]);
  EXPECT_GT(coverage(nu), 2000.0);
  EXPECT_LT(diff, 1.0) << "alpha differs by " << diff << " of " << coverage(nu);
}

TEST_F(RibNuPatchRender, CylinderAndSphereCoverTheirProjectedAreas) {
  // Seen from the side: a 2 x 2 rectangle, 32 pixels a unit.
  const double a = coverage(render(ortho_frame(2.5, "Rotate 90 1 0 0", cylinder()))) / (32.0 * 32.0);
  EXPECT_NEAR(a / 4.0, 1.0, 2e-3) << a;
  // The unit sphere from any side: the unit disc.
  const double s = coverage(render(ortho_frame(2.5, "Rotate 35 1 1 0", sphere()))) / (32.0 * 32.0);
  EXPECT_NEAR(s / kPi, 1.0, 2e-3) << s;
}

TEST_F(RibNuPatchRender, SphereHasNoGapSeenFromInside) {
  const char* views[] = {"", "Rotate 180 0 1 0", "Rotate 90 0 1 0", "Rotate -90 0 1 0", "Rotate 90 1 0 0",
                         "Rotate -90 1 0 0"};
  for (const char* offset : {"", "Translate 0.013 -0.021 0.017"})
    for (const char* view : views) {
      const RenderResult r = render("Format 96 96 1\nPixelSamples 4 4\nProjection \"perspective\" \"fov\" [100]\n"
                                    "Clipping 0.001 100\n" + std::string(view) + "\n" + offset +
                                    "\nWorldBegin\nSurface \"constant\"\n" + sphere() + "\nWorldEnd\n");
      int uncovered = 0;
      for (size_t i = 0; i < size_t(r.width) * r.height; ++i) uncovered += r.rgba[4 * i + 3] < 1.0f - 1e-3f;
      EXPECT_EQ(uncovered, 0) << "view \"" << view << "\" " << offset;
    }
}

TEST_F(RibNuPatchRender, RoundTripKeepsTheSurface) {
  const RibResult first = read_rib_string(ortho_frame(2.5, "Rotate 60 1 0 0", sphere()), "nu.rib");
  std::ostringstream written;
  write_rib(first.scene, written);
  const RibResult second = read_rib_string(written.str(), "written.rib");
  const double a = coverage(renderer_->render(first.scene)), b = coverage(renderer_->render(second.scene));
  EXPECT_GT(a, 2000.0);
  EXPECT_NEAR(a / b, 1.0, 1e-4);
}

TEST(RibNuPatch, BadSurfacesAreErrors) {
  auto message = [](const std::string& body) {
    try {
      read_rib_string("WorldBegin\n" + body + "\nWorldEnd\n", "nu.rib");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string P4 = "\"P\" [0 0 0 1 0 0 0 1 0 1 1 0]";
  EXPECT_NE(message("NuPatch 2 2 [0 0 1] 0 1 2 2 [0 0 1 1] 0 1 " + P4).find("uknot has 3 values"), std::string::npos);
  EXPECT_NE(message("NuPatch 2 2 [0 1 0 1] 0 1 2 2 [0 0 1 1] 0 1 " + P4).find("uknot decreases"), std::string::npos);
  EXPECT_NE(message("NuPatch 2 2 [0 0 1 1] 0 2 2 2 [0 0 1 1] 0 1 " + P4).find("is not within the knots' range"),
            std::string::npos);
  EXPECT_NE(message("NuPatch 2 3 [0 0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 " + P4).find("less than the order"), std::string::npos);
  EXPECT_NE(message("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0 1 0 0]").find("nu * nv = 4"),
            std::string::npos);
  EXPECT_NE(message("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 1 1 0 0 1 0 1 0 0 1 1 0 1]")
                .find("weight is not positive"),
            std::string::npos);
  EXPECT_NE(message("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Cs\" [1 0 0]").find("missing \"P\" or \"Pw\""),
            std::string::npos);
  // A bilinear NuPatch (order 2 both ways) is a flat quad.
  const std::vector<glm::vec3> cps = nets_of("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 " + P4);
  ASSERT_EQ(cps.size(), 16u);
  EXPECT_NEAR(cps[5].x, 1.0 / 3.0, 1e-6);
  EXPECT_NEAR(cps[5].y, 1.0 / 3.0, 1e-6);
}

}  // namespace
}  // namespace mp::test
