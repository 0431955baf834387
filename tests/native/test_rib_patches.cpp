// RIB patches: every basis converted to Bezier nets must describe the same
// surface. Each net is evaluated by de Casteljau and compared with the
// original patch evaluated directly in its own basis (P = U M G M^T V^T,
// RI spec 3.2 section 5.2), with the basis matrices written out here from
// the spec, independently of the reader.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "rib/rib_reader.h"

namespace {

using Mat = std::array<std::array<double, 4>, 4>;

const Mat kBezier = {{{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}}};
const Mat kBSpline = {{{-1 / 6.0, 3 / 6.0, -3 / 6.0, 1 / 6.0},
                       {3 / 6.0, -6 / 6.0, 3 / 6.0, 0},
                       {-3 / 6.0, 0, 3 / 6.0, 0},
                       {1 / 6.0, 4 / 6.0, 1 / 6.0, 0}}};
const Mat kCatmullRom = {{{-0.5, 1.5, -1.5, 0.5}, {1, -2.5, 2, -0.5}, {-0.5, 0, 0.5, 0}, {0, 1, 0, 0}}};
const Mat kHermite = {{{2, 1, -2, 1}, {-3, -2, 3, -1}, {0, 1, 0, 0}, {1, 0, 0, 0}}};
const Mat kPower = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};

struct NamedBasis {
  const char* name;
  const Mat* m;
  int step;
};
const NamedBasis kBases[] = {{"bezier", &kBezier, 3},
                             {"b-spline", &kBSpline, 1},
                             {"catmull-rom", &kCatmullRom, 1},
                             {"hermite", &kHermite, 2},
                             {"power", &kPower, 4}};

// Weights of the 4 geometry entries at t: [t^3 t^2 t 1] * M.
std::array<double, 4> weights(const Mat& m, double t) {
  const double T[4] = {t * t * t, t * t, t, 1};
  std::array<double, 4> w{};
  for (int k = 0; k < 4; ++k)
    for (int a = 0; a < 4; ++a) w[static_cast<size_t>(k)] += T[a] * m[static_cast<size_t>(a)][static_cast<size_t>(k)];
  return w;
}

// g[i + 4 j]: i along u.
glm::dvec3 eval_basis(const std::vector<glm::dvec3>& g, const Mat& mu, const Mat& mv, double u, double v) {
  const auto wu = weights(mu, u), wv = weights(mv, v);
  glm::dvec3 p(0.0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) p += wu[static_cast<size_t>(i)] * wv[static_cast<size_t>(j)] * g[static_cast<size_t>(i + 4 * j)];
  return p;
}

glm::dvec3 de_casteljau(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, double t) {
  const glm::dvec3 ab = glm::mix(a, b, t), bc = glm::mix(b, c, t), cd = glm::mix(c, d, t);
  return glm::mix(glm::mix(ab, bc, t), glm::mix(bc, cd, t), t);
}

// cp[4 j + i] from `first` in a flat control-point list.
glm::dvec3 eval_bezier(const std::vector<glm::vec3>& cps, size_t first, double u, double v) {
  glm::dvec3 rows[4];
  for (size_t j = 0; j < 4; ++j) {
    auto at = [&](size_t i) { return glm::dvec3(cps[first + 4 * j + i]); };
    rows[j] = de_casteljau(at(0), at(1), at(2), at(3), u);
  }
  return de_casteljau(rows[0], rows[1], rows[2], rows[3], v);
}

std::string points_array(const std::vector<glm::dvec3>& pts) {
  std::string s = "[";
  for (const auto& p : pts) s += " " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z);
  return s + " ]";
}

std::string matrix_array(const Mat& m) {
  std::string s = "[";
  for (const auto& row : m)
    for (double x : row) s += " " + std::to_string(x);
  return s + " ]";
}

// A deterministic, non-planar net (std::to_string keeps 6 decimals).
std::vector<glm::dvec3> test_points(int nu, int nv) {
  std::vector<glm::dvec3> pts;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      pts.emplace_back(i + 0.25 * std::sin(1.3 * j + 0.7 * i), j + 0.125 * std::cos(2.1 * i - j),
                       0.5 * std::sin(0.9 * i * j + 0.3) - 0.25 * i);
  return pts;
}

mp::RibResult parse_world(const std::string& body) {
  return mp::read_rib_string("WorldBegin\n" + body + "\nWorldEnd\n", "patch.rib");
}

const double kSamples[] = {0.0, 0.2, 0.5, 0.77, 1.0};

TEST(RibBasis, EveryNamedBasisPatchMatchesItsBezierNet) {
  const std::vector<glm::dvec3> g = test_points(4, 4);
  for (const NamedBasis& bu : kBases)
    for (const NamedBasis& bv : kBases) {
      const std::string rib = "Basis \"" + std::string(bu.name) + "\" " + std::to_string(bu.step) +
                              " \"" + bv.name + "\" " + std::to_string(bv.step) +
                              "\nPatch \"bicubic\" \"P\" " + points_array(g);
      const mp::RibResult r = parse_world(rib);
      ASSERT_EQ(r.scene.bezier_patches.size(), 1u);
      const auto& cps = r.scene.bezier_patches[0].control_points;
      ASSERT_EQ(cps.size(), 16u);
      for (double u : kSamples)
        for (double v : kSamples) {
          const glm::dvec3 want = eval_basis(g, *bu.m, *bv.m, u, v);
          const glm::dvec3 got = eval_bezier(cps, 0, u, v);
          EXPECT_NEAR(glm::length(got - want), 0.0, 2e-5)
              << bu.name << " x " << bv.name << " at (" << u << ", " << v << ")";
        }
    }
}

TEST(RibBasis, ExplicitMatrixBasis) {
  // An arbitrary (non-standard) basis matrix given as 16 numbers.
  const Mat m = {{{0.5, -1, 2, 0.25}, {1, 0.5, -0.5, 1}, {-2, 1, 0, 0.5}, {0.25, 0.5, 1, -1}}};
  const std::vector<glm::dvec3> g = test_points(4, 4);
  const mp::RibResult r = parse_world("Basis " + matrix_array(m) + " 1 \"catmull-rom\" 1\n" +
                                      "Patch \"bicubic\" \"P\" " + points_array(g));
  const auto& cps = r.scene.bezier_patches.at(0).control_points;
  for (double u : kSamples)
    for (double v : kSamples)
      EXPECT_NEAR(glm::length(eval_bezier(cps, 0, u, v) - eval_basis(g, m, kCatmullRom, u, v)), 0.0, 1e-4);
}

// PatchMesh: patch (pu, pv) uses vertices (pu * ustep + k) mod nu, likewise in v.
void check_patch_mesh(const NamedBasis& bu, const NamedBasis& bv, int nu, bool uper, int nv, bool vper,
                      int npu, int npv) {
  const std::vector<glm::dvec3> pts = test_points(nu, nv);
  const std::string rib = "Basis \"" + std::string(bu.name) + "\" " + std::to_string(bu.step) + " \"" +
                          bv.name + "\" " + std::to_string(bv.step) + "\nPatchMesh \"bicubic\" " +
                          std::to_string(nu) + (uper ? " \"periodic\" " : " \"nonperiodic\" ") +
                          std::to_string(nv) + (vper ? " \"periodic\" " : " \"nonperiodic\" ") +
                          "\"P\" " + points_array(pts);
  const mp::RibResult r = parse_world(rib);
  ASSERT_EQ(r.scene.bezier_patches.size(), 1u);
  const auto& cps = r.scene.bezier_patches[0].control_points;
  ASSERT_EQ(cps.size(), static_cast<size_t>(16 * npu * npv)) << rib;
  for (int pv = 0; pv < npv; ++pv)
    for (int pu = 0; pu < npu; ++pu) {
      std::vector<glm::dvec3> g(16);
      for (int l = 0; l < 4; ++l)
        for (int k = 0; k < 4; ++k)
          g[static_cast<size_t>(k + 4 * l)] =
              pts[static_cast<size_t>((pu * bu.step + k) % nu + nu * ((pv * bv.step + l) % nv))];
      const size_t first = static_cast<size_t>(16 * (pu + npu * pv));
      for (double u : kSamples)
        for (double v : kSamples)
          EXPECT_NEAR(glm::length(eval_bezier(cps, first, u, v) - eval_basis(g, *bu.m, *bv.m, u, v)), 0.0, 5e-5)
              << bu.name << "/" << bv.name << " patch " << pu << "," << pv;
    }
}

TEST(RibPatchMesh, NonperiodicAndPeriodicWithSteps) {
  const NamedBasis& bezier = kBases[0];
  const NamedBasis& bspline = kBases[1];
  const NamedBasis& catmull = kBases[2];
  const NamedBasis& hermite = kBases[3];
  const NamedBasis& power = kBases[4];
  check_patch_mesh(bezier, bezier, 7, false, 4, false, 2, 1);     // (7-4)/3+1
  check_patch_mesh(bspline, bspline, 6, false, 5, false, 3, 2);   // (6-4)/1+1, (5-4)/1+1
  check_patch_mesh(bspline, catmull, 5, true, 6, false, 5, 3);    // periodic: nu/step
  check_patch_mesh(catmull, bspline, 4, false, 4, true, 1, 4);
  check_patch_mesh(hermite, hermite, 6, false, 4, true, 2, 2);    // (6-4)/2+1, 4/2
  check_patch_mesh(power, bezier, 8, false, 4, false, 2, 1);      // (8-4)/4+1
}

TEST(RibPatchMesh, PeriodicBSplineIsClosedAndContinuous) {
  const std::vector<glm::dvec3> pts = test_points(6, 4);
  const mp::RibResult r = parse_world("Basis \"b-spline\" 1 \"b-spline\" 1\n"
                                      "PatchMesh \"bicubic\" 6 \"periodic\" 4 \"nonperiodic\" \"P\" " +
                                      points_array(pts));
  const auto& cps = r.scene.bezier_patches.at(0).control_points;
  ASSERT_EQ(cps.size(), 6u * 16u);
  for (size_t p = 0; p < 6; ++p) {
    const size_t next = (p + 1) % 6;  // wraps around: the last patch meets the first
    for (double v : kSamples)
      EXPECT_NEAR(glm::length(eval_bezier(cps, 16 * p, 1.0, v) - eval_bezier(cps, 16 * next, 0.0, v)), 0.0, 1e-5);
  }
}

TEST(RibPatchMesh, BilinearMeshesAndPatches) {
  // Bilinear: nonperiodic nu-1 patches, periodic nu patches; degree-elevated
  // nets reproduce bilinear interpolation exactly.
  const std::vector<glm::dvec3> pts = test_points(3, 2);
  const mp::RibResult r = parse_world("PatchMesh \"bilinear\" 3 \"periodic\" 2 \"nonperiodic\" \"P\" " +
                                      points_array(pts));
  const auto& cps = r.scene.bezier_patches.at(0).control_points;
  ASSERT_EQ(cps.size(), 3u * 16u);
  for (int pu = 0; pu < 3; ++pu) {
    const glm::dvec3 p00 = pts[static_cast<size_t>(pu)], p10 = pts[static_cast<size_t>((pu + 1) % 3)];
    const glm::dvec3 p01 = pts[static_cast<size_t>(3 + pu)], p11 = pts[static_cast<size_t>(3 + (pu + 1) % 3)];
    for (double u : kSamples)
      for (double v : kSamples) {
        const glm::dvec3 want = glm::mix(glm::mix(p00, p10, u), glm::mix(p01, p11, u), v);
        EXPECT_NEAR(glm::length(eval_bezier(cps, static_cast<size_t>(16 * pu), u, v) - want), 0.0, 1e-5);
      }
  }
}

TEST(RibPatchMesh, WrongCountsAreErrors) {
  auto error = [](const std::string& body) -> std::string {
    try {
      parse_world(body);
    } catch (const mp::RibError& e) {
      return e.what();
    }
    return "";
  };
  // Bezier step 3 needs 4 + 3k vertices.
  EXPECT_NE(error("PatchMesh \"bicubic\" 5 \"nonperiodic\" 4 \"nonperiodic\" \"P\" " +
                  points_array(test_points(5, 4))).find("patch.rib:2: PatchMesh: nu = 5"), std::string::npos);
  // P must hold nu * nv points.
  EXPECT_NE(error("PatchMesh \"bicubic\" 4 \"nonperiodic\" 4 \"nonperiodic\" \"P\" " +
                  points_array(test_points(4, 3))).find("nu * nv = 16"), std::string::npos);
  // A 2^31 - 1 count allocates nothing: it fails on the point count.
  EXPECT_NE(error("PatchMesh \"bilinear\" 2147483647 \"nonperiodic\" 2147483647 \"nonperiodic\" \"P\" " +
                  points_array(test_points(2, 2))).find("nu * nv"), std::string::npos);
  EXPECT_NE(error("Patch \"bicubic\" \"P\" " + points_array(test_points(3, 3))).find("needs 16 points"),
            std::string::npos);
  EXPECT_NE(error("Patch \"biquadratic\" \"P\" [0 0 0]").find("patch type"), std::string::npos);
  EXPECT_NE(error("PatchMesh \"bicubic\" 4 \"sometimes\" 4 \"nonperiodic\" \"P\" [0 0 0]").find("wrap mode"),
            std::string::npos);
  EXPECT_NE(error("Basis \"nurbs\" 1 \"bezier\" 3").find("unknown basis"), std::string::npos);
  EXPECT_NE(error("Basis [1 2 3] 1 \"bezier\" 3").find("16 numbers"), std::string::npos);
  EXPECT_NE(error("Basis \"bezier\" 0 \"bezier\" 3").find("integer in [1"), std::string::npos);
}

TEST(RibPatchMesh, RationalPatchesWarn) {
  const mp::RibResult r = parse_world("Patch \"bilinear\" \"Pw\" [0 0 0 1  2 0 0 2  0 1 0 1  1 1 0 1]");
  ASSERT_EQ(r.scene.bezier_patches.size(), 1u);
  EXPECT_EQ(r.scene.bezier_patches[0].control_points[3], glm::vec3(1, 0, 0));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("rational"), std::string::npos);
}

// --- the Utah teapot ------------------------------------------------------------------------

TEST(RibTeapot, ThirtyTwoBezierPatches) {
  const mp::RibResult r = mp::read_rib_file(std::string(MICROPOLY_TEST_SCENES) + "/teapot.rib");
  EXPECT_TRUE(r.warnings.empty());
  const mp::Scene& s = r.scene;
  EXPECT_EQ(s.settings.width, 640);
  EXPECT_EQ(s.settings.height, 480);
  EXPECT_EQ(r.display_name, "teapot.png");
  ASSERT_EQ(s.bezier_patches.size(), 1u);  // 32 Patch requests with one state: one set
  const mp::BezierPatches& teapot = s.bezier_patches[0];
  EXPECT_EQ(teapot.name, "teapot");
  ASSERT_EQ(teapot.control_points.size(), 32u * 16u);
  // Bezier patches pass through unchanged: the rim patch starts at (1.4, 0, 2.4).
  EXPECT_EQ(teapot.control_points[0], glm::vec3(1.4f, 0.0f, 2.4f));
  EXPECT_EQ(teapot.control_points[15], glm::vec3(0.0f, -1.5f, 2.4f));
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : teapot.control_points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  EXPECT_EQ(lo, glm::vec3(-3.0f, -2.0f, 0.0f));
  EXPECT_EQ(hi, glm::vec3(3.525f, 2.0f, 3.15f));
  const mp::Material& m = s.materials[static_cast<size_t>(teapot.material)];
  EXPECT_EQ(m.model, mp::Material::Model::Plastic);
  EXPECT_EQ(s.lights.size(), 3u);
  // The whole teapot is in front of the camera and inside the 4:3 frame.
  const float t = std::tan(glm::radians(s.camera.fov_degrees) * 0.5f);
  for (const glm::vec3& p : teapot.control_points) {
    const glm::vec4 c = s.camera.world_to_camera * teapot.object_to_world * glm::vec4(p, 1.0f);
    ASSERT_LT(c.z, 0.0f);
    EXPECT_LT(std::fabs(c.x / (-c.z * t)), 4.0f / 3.0f);
    EXPECT_LT(std::fabs(c.y / (-c.z * t)), 1.0f);
  }
}

}  // namespace
