// RenderMan's quadrics from RIB (rib_quadrics.h), checked against the RI
// spec's own definitions (section 5.4) and analytic geometry:
//  - every net's surface lies on its quadric, within the sweep;
//  - the nets' area, integrated numerically, is the quadric's analytic area;
//  - neighbouring nets share bit-identical edges, poles are single points;
//  - rendered coverage (orthographic, 16 spp) is the analytic projected area;
//  - normals face as RenderMan's (Sides 1 hides the same side);
//  - a camera inside a sphere or a torus' tube sees no gap at any seam.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "renderer_fixture.h"
#include "rib/rib_reader.h"

namespace mp::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 cubic(const glm::dvec3 p[4], double t, glm::dvec3* d = nullptr) {
  const double s = 1.0 - t;
  if (d) *d = 3.0 * (s * s * (p[1] - p[0]) + 2.0 * s * t * (p[2] - p[1]) + t * t * (p[3] - p[2]));
  return s * s * s * p[0] + 3.0 * s * s * t * p[1] + 3.0 * s * t * t * p[2] + t * t * t * p[3];
}

// Point and partial derivatives of net `n` (cps[16 n + 4 j + i], i along u).
glm::dvec3 eval_net(const std::vector<glm::vec3>& cps, size_t n, double u, double v, glm::dvec3* du,
                    glm::dvec3* dv) {
  glm::dvec3 rows[4], drows[4];
  for (size_t j = 0; j < 4; ++j) {
    glm::dvec3 p[4];
    for (size_t i = 0; i < 4; ++i) p[i] = glm::dvec3(cps[16 * n + 4 * j + i]);
    rows[j] = cubic(p, u, &drows[j]);
  }
  glm::dvec3 unused;
  if (du) *du = cubic(drows, v, &unused);
  return cubic(rows, v, dv);
}

// Gauss-Legendre, 8 points on [0, 1].
const double kNodes[8] = {0.0198550717512319, 0.1016667612931866, 0.2372337950418355, 0.4082826787521751,
                          0.5917173212478249, 0.7627662049581645, 0.8983332387068134, 0.9801449282487681};
const double kWeights[8] = {0.0506142681451881, 0.1111905172266872, 0.1568533229389436, 0.1813418916891810,
                            0.1813418916891810, 0.1568533229389436, 0.1111905172266872, 0.0506142681451881};

double nets_area(const std::vector<glm::vec3>& cps) {
  double area = 0.0;
  for (size_t n = 0; n < cps.size() / 16; ++n)
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b) {
        glm::dvec3 du, dv;
        eval_net(cps, n, kNodes[a], kNodes[b], &du, &dv);
        area += kWeights[a] * kWeights[b] * glm::length(glm::cross(du, dv));
      }
  return area;
}

struct Case {
  std::string request;
  // Distance of a point from the surface, relative to the quadric's size
  // (its largest radius).
  std::function<double(const glm::dvec3&)> residual;
  double area;        // analytic
  double theta_max;   // degrees
};

double rho(const glm::dvec3& p) { return std::hypot(p.x, p.y); }

std::vector<Case> cases() {
  const double d2r = kPi / 180.0;
  std::vector<Case> c;
  c.push_back({"Sphere 1.5 -1.5 1.5 360", [](const glm::dvec3& p) { return std::fabs(glm::length(p) - 1.5) / 1.5; },
               4.0 * kPi * 1.5 * 1.5, 360.0});
  // A zone: z from -0.5 to 1 of a radius 2 sphere, a 250 degree sweep.
  c.push_back({"Sphere 2 -0.5 1 250", [](const glm::dvec3& p) { return std::fabs(glm::length(p) - 2.0) / 2.0; },
               250.0 / 360.0 * 2.0 * kPi * 2.0 * 1.5, 250.0});
  c.push_back({"Cylinder 0.75 -1 2 360", [](const glm::dvec3& p) { return std::fabs(rho(p) - 0.75) / 0.75; },
               2.0 * kPi * 0.75 * 3.0, 360.0});
  c.push_back({"Cone 2 1 -120", [](const glm::dvec3& p) { return std::fabs(rho(p) - (1.0 - p.z / 2.0)); },
               120.0 / 360.0 * kPi * 1.0 * std::sqrt(5.0), -120.0});
  c.push_back({"Disk 0.5 1.25 300",
               [](const glm::dvec3& p) { return std::fabs(p.z - 0.5) + std::max(0.0, rho(p) - 1.25); },
               300.0 / 360.0 * kPi * 1.25 * 1.25, 300.0});
  {
    // z = zmax (rho / rmax)^2, z from 0.25 to 2: area of a surface of revolution.
    const double rmax = 1.2, zmax = 2.0, a = zmax / (rmax * rmax);
    const double r0 = rmax * std::sqrt(0.25 / zmax), r1 = rmax;
    auto F = [&](double r) { return std::pow(1.0 + 4.0 * a * a * r * r, 1.5) / (12.0 * a * a); };
    c.push_back({"Paraboloid 1.2 0.25 2 360",
                 [=](const glm::dvec3& p) { return std::fabs(p.z - a * rho(p) * rho(p)) / zmax; },
                 2.0 * kPi * (F(r1) - F(r0)), 360.0});
  }
  {
    // The line from p1 to p2 swept about z; its area by Simpson's rule over
    // the exact sweep (|dP/dtheta x dP/dv| does not depend on theta).
    const glm::dvec3 p1(1.0, -0.5, -1.0), p2(0.4, 0.8, 1.0), d = p2 - p1;
    double integral = 0.0;
    const int n = 2000;
    for (int k = 0; k <= n; ++k) {
      const glm::dvec3 L = p1 + d * (double(k) / n), dtheta(-L.y, L.x, 0.0);
      const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      integral += w * glm::length(glm::cross(dtheta, d));
    }
    integral /= 3.0 * n;
    c.push_back({"Hyperboloid 1 -0.5 -1 0.4 0.8 1 360",
                 [=](const glm::dvec3& p) {
                   const glm::dvec3 L = glm::mix(p1, p2, (p.z - p1.z) / (p2.z - p1.z));
                   return std::fabs(rho(p) - rho(L));
                 },
                 2.0 * kPi * integral, 360.0});
  }
  c.push_back({"Torus 1 0.3 0 360 360",
               [](const glm::dvec3& p) { return std::fabs(std::hypot(rho(p) - 1.0, p.z) - 0.3) / 1.3; },
               4.0 * kPi * kPi * 1.0 * 0.3, 360.0});
  {
    // phi from -60 to 200 degrees, a 90 degree sweep.
    const double R = 1.5, r = 0.5, f0 = -60.0 * d2r, f1 = 200.0 * d2r;
    c.push_back({"Torus 1.5 0.5 -60 200 90",
                 [=](const glm::dvec3& p) { return std::fabs(std::hypot(rho(p) - R, p.z) - r) / (R + r); },
                 90.0 * d2r * r * (R * (f1 - f0) + r * (std::sin(f1) - std::sin(f0))), 90.0});
  }
  return c;
}

std::vector<glm::vec3> nets_of(const std::string& request) {
  RibResult r = read_rib_string("WorldBegin\n" + request + "\nWorldEnd\n", "quadric.rib");
  if (r.scene.bezier_patches.size() != 1) {
    ADD_FAILURE() << request << ": " << r.scene.bezier_patches.size() << " patch sets";
    return {};
  }
  return r.scene.bezier_patches[0].control_points;
}

TEST(RibQuadrics, NetsLieOnTheirQuadricWithinTheSweep) {
  for (const Case& c : cases()) {
    const std::vector<glm::vec3> cps = nets_of(c.request);
    ASSERT_FALSE(cps.empty()) << c.request;
    double worst = 0.0, outside = 0.0;
    for (size_t n = 0; n < cps.size() / 16; ++n)
      for (int a = 0; a <= 8; ++a)
        for (int b = 0; b <= 8; ++b) {
          const glm::dvec3 p = eval_net(cps, n, a / 8.0, b / 8.0, nullptr, nullptr);
          worst = std::max(worst, c.residual(p));
          if (rho(p) > 1e-6 && std::fabs(c.theta_max) < 360.0) {
            // The angle about z, measured in the sweep's direction.
            double t = std::atan2(p.y, p.x) * 180.0 / kPi * (c.theta_max < 0 ? -1.0 : 1.0);
            if (t < -1e-3) t += 360.0;
            outside = std::max(outside, t - std::fabs(c.theta_max));
          }
        }
    // A cubic arc of 45 degrees deviates radially by at most 4.3e-6 of its
    // radius; a sphere or torus sweeps one arc along another.
    EXPECT_LT(worst, 1e-5) << c.request;
    EXPECT_LT(outside, 1e-3) << c.request << ": degrees past thetamax";
  }
}

TEST(RibQuadrics, NetsHaveTheQuadricsArea) {
  for (const Case& c : cases()) {
    const double area = nets_area(nets_of(c.request));
    EXPECT_NEAR(area / c.area, 1.0, 2e-5) << c.request << ": " << area << " against " << c.area;
  }
}

// Each net edge's four control points, by their bits, in a direction-free order.
using EdgeKey = std::array<uint32_t, 12>;
EdgeKey edge_key(std::array<glm::vec3, 4> e) {
  auto bits = [](const std::array<glm::vec3, 4>& pts) {
    EdgeKey k{};
    std::memcpy(k.data(), pts.data(), sizeof k);
    return k;
  };
  const EdgeKey forward = bits(e);
  std::swap(e[0], e[3]);
  std::swap(e[1], e[2]);
  return std::min(forward, bits(e));
}

TEST(RibQuadrics, ClosedQuadricsShareEveryEdgeBitForBit) {
  for (const char* request : {"Sphere 1 -1 1 360", "Torus 2 0.5 0 360 360", "Sphere 0.7 -2 2 -360"}) {
    const std::vector<glm::vec3> cps = nets_of(request);
    ASSERT_FALSE(cps.empty());
    std::map<EdgeKey, int> uses;
    int poles = 0;
    for (size_t n = 0; n < cps.size() / 16; ++n) {
      const glm::vec3* p = &cps[16 * n];
      const std::array<std::array<glm::vec3, 4>, 4> edges = {{{p[0], p[1], p[2], p[3]},
                                                              {p[12], p[13], p[14], p[15]},
                                                              {p[0], p[4], p[8], p[12]},
                                                              {p[3], p[7], p[11], p[15]}}};
      for (const auto& e : edges) {
        if (std::memcmp(&e[0], &e[1], sizeof e[0]) == 0 && std::memcmp(&e[0], &e[2], sizeof e[0]) == 0 &&
            std::memcmp(&e[0], &e[3], sizeof e[0]) == 0) {
          ++poles;  // a pole: one point
          continue;
        }
        ++uses[edge_key(e)];
      }
    }
    for (const auto& [key, count] : uses) EXPECT_EQ(count, 2) << request << ": an edge used " << count << " times";
    EXPECT_EQ(poles, std::string(request).rfind("Torus", 0) == 0 ? 0 : 16) << request;
  }
}

// A RIB frame around one quadric; an orthographic camera looking along +z at
// the window [-s, s]^2 from 5 units away, 160 x 160 pixels at 16 spp.
std::string ortho_frame(double s, const std::string& body) {
  return "Format 160 160 1\nPixelSamples 4 4\nProjection \"orthographic\"\nScreenWindow " + std::to_string(-s) + " " +
         std::to_string(s) + " " + std::to_string(-s) + " " + std::to_string(s) +
         "\nTranslate 0 0 5\nWorldBegin\nSurface \"constant\"\n" + body + "\nWorldEnd\n";
}

class RibQuadricsRender : public SharedRendererTest {
 protected:
  RenderResult render(const std::string& rib) {
    RibResult r = read_rib_string(rib, "quadric.rib");
    return renderer_->render(r.scene);
  }
};

TEST_F(RibQuadricsRender, CoverageIsTheProjectedArea) {
  struct Shot {
    std::string body;
    double area;  // projected, in scene units
  };
  const double s = 2.0, px = 80.0 / s;  // pixels per unit
  const Shot shots[] = {
      {"Sphere 1.5 -1.5 1.5 360", kPi * 1.5 * 1.5},
      // Seen along z: the annulus between R - r and R + r.
      {"Torus 1.2 0.4 0 360 360", kPi * (1.6 * 1.6 - 0.8 * 0.8)},
      // Seen from the side: a 1.6 x 3 rectangle, a triangle of base 2 and height 1.5.
      {"Rotate 90 1 0 0\nCylinder 0.8 -1.5 1.5 360", 1.6 * 3.0},
      {"Rotate 90 1 0 0\nTranslate 0 0 -0.75\nCone 1.5 1 360", 1.5},
      {"Disk 0 1.8 90", kPi * 1.8 * 1.8 / 4.0},
      // The line (1, -1.5 + 3t, -1 + 2t) swept: along z, the annulus of radii 1 and sqrt(3.25).
      {"Hyperboloid 1 -1.5 -1 1 1.5 1 360", kPi * 2.25},
      {"Paraboloid 1.4 0 1 360", kPi * 1.4 * 1.4},
  };
  for (const Shot& shot : shots) {
    const double got = coverage(render(ortho_frame(s, shot.body))) / (px * px);
    EXPECT_NEAR(got / shot.area, 1.0, 2e-3) << shot.body << ": " << got << " against " << shot.area;
  }
}

TEST_F(RibQuadricsRender, SidesOneHidesTheSideRenderManHides) {
  // The camera looks along +z: a Disk's normal (+z) and the outside of the
  // upper half sphere's bowl face away from it, so with Sides 1 both are
  // hidden, and ReverseOrientation shows them.
  for (const char* body : {"Disk 0 1.5 360", "Sphere 1.5 0 1.5 360"}) {
    const double front = coverage(render(ortho_frame(2.0, std::string("Sides 1\n") + body)));
    const double reversed = coverage(render(ortho_frame(2.0, std::string("Sides 1\nReverseOrientation\n") + body)));
    const double area = kPi * 1.5 * 1.5 * 40.0 * 40.0;
    EXPECT_LT(front, 1e-3 * area) << body;
    EXPECT_NEAR(reversed / area, 1.0, 2e-3) << body;
  }
}

// Pixels with alpha below 1 (a gap at a seam or pole shows the background).
int uncovered(const RenderResult& r) {
  int n = 0;
  for (size_t i = 0; i < size_t(r.width) * r.height; ++i) n += r.rgba[4 * i + 3] < 1.0f - 1e-3f;
  return n;
}

std::string inside_frame(const std::string& camera, const std::string& body) {
  return "Format 96 96 1\nPixelSamples 4 4\nProjection \"perspective\" \"fov\" [100]\nClipping 0.001 100\n" + camera +
         "\nWorldBegin\nSurface \"constant\"\n" + body + "\nWorldEnd\n";
}

TEST_F(RibQuadricsRender, NoGapSeenFromInside) {
  // The six axis views from a sphere's centre, and from near it, see both
  // poles and the seam. From the centre the equator lies in the eye plane
  // (within the rotations' rounding): patches whose boxes straddle the eye
  // plane are split, never culled as hidden by what is already sampled.
  const char* views[] = {"", "Rotate 180 0 1 0", "Rotate 90 0 1 0", "Rotate -90 0 1 0", "Rotate 90 1 0 0",
                         "Rotate -90 1 0 0"};
  for (const char* offset : {"", "Translate 0.013 -0.021 0.017"})
    for (const char* view : views) {
      const RenderResult r = render(inside_frame(std::string(view) + "\n" + offset, "Sphere 1 -1 1 360"));
      EXPECT_EQ(uncovered(r), 0) << "sphere, view \"" << view << "\" " << offset;
    }
  // From the centre of a torus' tube at theta = -15 degrees, looking along
  // the tube across the theta = 0 seam (the phi seam runs along its outside).
  const RenderResult r = render(inside_frame("", "Rotate 90 1 0 0\nTranslate -1.5 0 0\nRotate 15 0 0 1\n"
                                                 "Torus 1.5 0.4 0 360 360"));
  EXPECT_EQ(uncovered(r), 0) << "torus";
}

TEST(RibQuadrics, ParaboloidAcrossZeroIsAnError) {
  try {
    read_rib_string("WorldBegin\nParaboloid 1 -1 1 360\nWorldEnd\n", "quadric.rib");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("quadric.rib:2: Paraboloid: zmin and zmax must not lie on both sides of 0"),
              std::string::npos)
        << e.what();
  }
}

TEST(RibQuadrics, NoAreaIsSkippedWithAWarning) {
  RibResult r = read_rib_string("WorldBegin\nSphere 0 -1 1 360\nDisk 0 1 0\nSphere 1 -1 1 360 \"Cs\" [1 0 0]\nWorldEnd\n",
                                "quadric.rib");
  EXPECT_EQ(r.scene.bezier_patches.size(), 1u);
  int skipped = 0, ignored = 0;
  for (const std::string& w : r.warnings) {
    skipped += w.find("with no area") != std::string::npos;
    ignored += w.find("\"Cs\" is ignored") != std::string::npos;
  }
  EXPECT_EQ(skipped, 2);
  EXPECT_EQ(ignored, 1);
}

}  // namespace
}  // namespace mp::test
