// Stochastic opacity (kernels/stages/mp_sample.h, mp_opacity_keeps): a
// pixel keeps its share of a surface's samples almost exactly, and surfaces
// seen through one another draw their own thresholds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class StochasticOpacityTest : public SharedRendererTest {};

constexpr int kSize = 64, kSpp = 16;

// A camera above the origin looking down on planes that fill its view.
Scene planes(const std::vector<float>& opacities) {
  Scene s = base_scene(kSize, kSize, kSpp);
  s.camera = look_at({0.0f, 0.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, 30.0f);
  for (size_t k = 0; k < opacities.size(); ++k) {
    Material m;
    m.model = Material::Model::Matte;
    m.color = glm::vec3(0.5f);
    m.opacity = glm::vec3(opacities[k]);
    s.materials.push_back(m);
    const float z = -float(k);
    Mesh plane = polygon({{-5, -5, z}, {5, -5, z}, {5, 5, z}, {-5, 5, z}});
    plane.name = "plane" + std::to_string(k);
    plane.material = int(s.materials.size()) - 1;
    s.meshes.push_back(plane);
  }
  return s;
}

// The largest difference between a pixel's alpha and `expected`, and the mean alpha.
void alpha_spread(const RenderResult& r, float expected, float& worst, float& mean) {
  worst = 0.0f, mean = 0.0f;
  for (int i = 0; i < kSize * kSize; ++i) {
    const float a = r.rgba[size_t(i) * 4 + 3];
    worst = std::max(worst, std::fabs(a - expected));
    mean += a / float(kSize * kSize);
  }
}

// Sixteen independent draws per pixel at opacity 0.5 leave about three
// pixels in ten two or more samples from eight; thresholds spread over the
// pixel's samples (the golden-ratio sequence) keep every pixel within 1.2.
TEST_F(StochasticOpacityTest, EveryPixelKeepsItsShareOfTheSamples) {
  for (float opacity : {0.3f, 0.5f, 0.7f}) {
    const RenderResult r = renderer_->render(planes({opacity}));
    float worst, mean;
    alpha_spread(r, opacity, worst, mean);
    EXPECT_NEAR(mean, opacity, 0.01f) << "opacity " << opacity;
    EXPECT_LE(worst, 1.5f / kSpp) << "opacity " << opacity << ": a pixel strays from its share";
  }
}

// Two half-transparent planes, one over the other: a sample keeps the near
// one half the time and the far one half of the rest, 3/4 in all. Shared
// thresholds would keep the far plane only where the near one also kept
// the sample, hidden behind it: 1/2.
TEST_F(StochasticOpacityTest, SurfacesSeenThroughOneAnotherDrawTheirOwnThresholds) {
  const RenderResult r = renderer_->render(planes({0.5f, 0.5f}));
  float worst, mean;
  alpha_spread(r, 0.75f, worst, mean);
  EXPECT_NEAR(mean, 0.75f, 0.02f);
}

}  // namespace
}  // namespace mp::test
