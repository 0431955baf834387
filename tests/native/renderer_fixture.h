// A test fixture with one Renderer (one kernel build) per test suite. If the
// renderer cannot be created, every test of the suite fails with the reason
// instead of being skipped.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "micropoly/renderer.h"

namespace mp::test {

class SharedRendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    try {
      renderer_ = std::make_unique<Renderer>();
    } catch (const std::exception& e) {
      setup_error_ = e.what();
    }
  }
  static void TearDownTestSuite() { renderer_.reset(); }
  void SetUp() override { ASSERT_TRUE(renderer_) << "no renderer: " << setup_error_; }

  static inline std::unique_ptr<Renderer> renderer_;
  static inline std::string setup_error_;
};

// The image's alpha summed: how many pixels its surfaces cover.
inline double coverage(const RenderResult& r) {
  double sum = 0.0;
  for (size_t i = 3; i < r.rgba.size(); i += 4) sum += r.rgba[i];
  return sum;
}

}  // namespace mp::test
