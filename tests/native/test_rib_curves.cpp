// RIB Curves (rib/rib_curves.cpp): linear and cubic curves in every basis,
// periodic or not, as ribbons facing the eye. Coverage against the analytic areas of
// the strips they project to, the same curve through different bases, and
// the request's errors.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "renderer_fixture.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Orthographic, looking down -z at the window [-2.5, 2.5] x [-1.875, 1.875]
// on 160 x 120 pixels (32 a unit).
const char* kHead =
    "Format 160 120 1\nPixelSamples 4 4\nProjection \"orthographic\"\nScreenWindow -2.5 2.5 -1.875 1.875\n"
    "Translate 0 0 5\nWorldBegin\nSurface \"constant\"\n";
constexpr double kPixelsPerUnit = 32.0;

RibResult read(const std::string& body) { return read_rib_string(std::string(kHead) + body + "\nWorldEnd\n", "c.rib"); }

class RibCurvesTest : public SharedRendererTest {
 protected:
  double area(const std::string& body) {
    return coverage(renderer_->render(read(body).scene)) / (kPixelsPerUnit * kPixelsPerUnit);
  }
};

TEST_F(RibCurvesTest, LinearCurveCoversItsStrip) {
  // 3 long, 0.2 wide, a turn of 90 degrees at its middle vertex: the strip's
  // area, less nothing at the open ends (ribbons facing the eye are width x length).
  const double a = area("Curves \"linear\" [3] \"nonperiodic\" \"P\" [-1.5 -0.5 0  0 -0.5 0  0 1 0] \"constantwidth\" [0.2]");
  // Two legs of 1.5 meeting at a right angle: the outer corner's square
  // quarter (0.1 x 0.1) is covered, the inner overlap counted once.
  EXPECT_NEAR(a / (3.0 * 0.2), 1.0, 0.02) << a;
}

TEST_F(RibCurvesTest, TaperedWidthsPerSegmentEnd) {
  // Varying widths: 0.4 at the left end, 0.1 at the right, linear between:
  // a trapezoid of mean width 0.25.
  const double a = area("Curves \"linear\" [2] \"nonperiodic\" \"P\" [-2 0 0  2 0 0] \"width\" [0.4 0.1]");
  EXPECT_NEAR(a / (4.0 * 0.25), 1.0, 0.01) << a;
}

TEST_F(RibCurvesTest, BasesDrawTheSameCurve) {
  // A B-spline and the Bezier segments it equals (the uniform cubic
  // B-spline's conversion), and the Catmull-Rom spline through the same
  // curve's points, cover the same pixels.
  const std::string bspline =
      "Basis \"b-spline\" 1 \"b-spline\" 1\nCurves \"cubic\" [6] \"nonperiodic\" \"P\" [-2 -1 0  -1.2 1 0  -0.4 -1 0  "
      "0.4 1 0  1.2 -1 0  2 1 0] \"constantwidth\" [0.15]";
  const RibResult b = read(bspline);
  ASSERT_EQ(b.scene.bezier_patches.size(), 1u);
  // Three segments, one ribbon patch each (scene/curves.cpp).
  EXPECT_TRUE(b.scene.bezier_patches[0].ribbons);
  EXPECT_EQ(b.scene.bezier_patches[0].control_points.size(), 3u * 16u);
  // The same segments written as a Bezier curve: each B-spline segment's
  // Bezier points are (p0 + 4p1 + p2)/6, (2p1 + p2)/3, (p1 + 2p2)/3, (p1 + 4p2 + p3)/6.
  const double xs[6] = {-2, -1.2, -0.4, 0.4, 1.2, 2}, ys[6] = {-1, 1, -1, 1, -1, 1};
  std::string P;
  for (int s = 0; s < 3; ++s) {
    const double* x = xs + s;
    const double* y = ys + s;
    auto put = [&](double px, double py) { P += std::to_string(px) + " " + std::to_string(py) + " 0  "; };
    if (s == 0) put((x[0] + 4 * x[1] + x[2]) / 6, (y[0] + 4 * y[1] + y[2]) / 6);
    put((2 * x[1] + x[2]) / 3, (2 * y[1] + y[2]) / 3);
    put((x[1] + 2 * x[2]) / 3, (y[1] + 2 * y[2]) / 3);
    put((x[1] + 4 * x[2] + x[3]) / 6, (y[1] + 4 * y[2] + y[3]) / 6);
  }
  const RenderResult rb = renderer_->render(b.scene);
  const RenderResult rz = renderer_->render(
      read("Basis \"bezier\" 3 \"bezier\" 3\nCurves \"cubic\" [10] \"nonperiodic\" \"P\" [" + P + "] \"constantwidth\" [0.15]")
          .scene);
  double diff = 0.0, total = 0.0;
  for (size_t i = 0; i < size_t(rb.width) * rb.height; ++i) {
    diff += std::fabs(rb.rgba[4 * i + 3] - rz.rgba[4 * i + 3]);
    total += rb.rgba[4 * i + 3];
  }
  EXPECT_NEAR(total / (kPixelsPerUnit * kPixelsPerUnit), 0.48, 0.05) << coverage(rz);
  EXPECT_LT(diff / total, 1e-3) << diff << " of " << total;
}

TEST_F(RibCurvesTest, PeriodicCurveClosesIntoARing) {
  // 12 B-spline control points on a circle of radius 1.2: a closed, nearly
  // circular curve (a uniform cubic B-spline of n points on a circle of
  // radius R is a curve of radius R (4 + 2 cos(2 pi / n)) / 6 at its knots);
  // 0.1 wide, it covers an annulus of 2 pi r x 0.1.
  std::string P;
  const int n = 12;
  for (int i = 0; i < n; ++i)
    P += std::to_string(1.2 * std::cos(2 * kPi * i / n)) + " " + std::to_string(1.2 * std::sin(2 * kPi * i / n)) + " 0  ";
  const double r = 1.2 * (4.0 + 2.0 * std::cos(2 * kPi / n)) / 6.0;
  const double a = area("Basis \"b-spline\" 1 \"b-spline\" 1\nCurves \"cubic\" [12] \"periodic\" \"P\" [" + P +
                        "] \"constantwidth\" [0.1]");
  EXPECT_NEAR(a / (2 * kPi * r * 0.1), 1.0, 0.02) << a;
}

TEST_F(RibCurvesTest, RoundTripKeepsTheCurves) {
  const RibResult first = read(
      "Curves \"cubic\" [4 7] \"nonperiodic\" \"P\" [-2 0 0  -1 1 0  0 -1 0  1 0 0   -2 -1 0  -1 -1.5 0  0 -1 0  1 -1.5 0  "
      "1.5 -1 0  2 -1.2 0  2 -0.5 0] \"width\" [0.1 0.2  0.05 0.1 0.2]");
  ASSERT_EQ(first.scene.bezier_patches.size(), 1u);
  std::ostringstream written;
  write_rib(first.scene, written);
  const RibResult second = read_rib_string(written.str(), "written.rib");
  ASSERT_EQ(second.scene.bezier_patches.size(), 1u);
  EXPECT_TRUE(second.scene.bezier_patches[0].ribbons);  // ribbons stay ribbons
  EXPECT_FALSE(second.scene.bezier_patches[0].round_u);
  EXPECT_EQ(second.scene.bezier_patches[0].control_points, first.scene.bezier_patches[0].control_points);
  const double a = coverage(renderer_->render(first.scene)), b = coverage(renderer_->render(second.scene));
  EXPECT_GT(a, 300.0);
  EXPECT_NEAR(a / b, 1.0, 1e-4);
}

TEST(RibCurves, BadCurvesAreErrorsOrSkipped) {
  auto message = [](const std::string& body) {
    try {
      read_rib_string("WorldBegin\n" + body + "\nWorldEnd\n", "c.rib");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("Curves \"quintic\" [2] \"nonperiodic\" \"P\" [0 0 0 1 0 0]").find("curve type must be"),
            std::string::npos);
  EXPECT_NE(message("Curves \"linear\" [2] \"sideways\" \"P\" [0 0 0 1 0 0]").find("wrap must be"), std::string::npos);
  EXPECT_NE(message("Curves \"cubic\" [5] \"nonperiodic\" \"P\" [0 0 0 1 0 0 2 0 0 3 0 0 4 0 0]").find("cannot use"),
            std::string::npos);
  EXPECT_NE(message("Curves \"linear\" [3] \"nonperiodic\" \"P\" [0 0 0 1 0 0]").find("nvertices adds up to 3"),
            std::string::npos);
  EXPECT_NE(message("Curves \"linear\" [2] \"nonperiodic\" \"width\" [1 1]").find("missing \"P\""), std::string::npos);
  EXPECT_NE(message("Curves \"linear\" [3] \"nonperiodic\" \"P\" [0 0 0 1 0 0 2 0 0] \"width\" [1 1]")
                .find("\"width\" has 2 values"),
            std::string::npos);
  const RibResult with_n = read_rib_string(
      "WorldBegin\nCurves \"linear\" [2] \"nonperiodic\" \"P\" [0 0 0 1 0 0] \"N\" [0 0 1 0 0 1]\nWorldEnd\n", "c.rib");
  ASSERT_EQ(with_n.warnings.size(), 1u);
  EXPECT_NE(with_n.warnings[0].find("\"N\" is ignored"), std::string::npos) << with_n.warnings[0];
  const RibResult skipped = read_rib_string(
      "WorldBegin\nCurves \"linear\" [2 2] \"nonperiodic\" \"P\" [0 0 0 1 0 0  0 1 0 1 1 0] \"width\" [0.1 0.1 0.1 -1]\n"
      "WorldEnd\n",
      "c.rib");
  ASSERT_EQ(skipped.scene.bezier_patches.size(), 1u);
  EXPECT_EQ(skipped.scene.bezier_patches[0].control_points.size(), 16u);
  EXPECT_EQ(skipped.warnings.size(), 1u);
}

}  // namespace
}  // namespace mp::test
