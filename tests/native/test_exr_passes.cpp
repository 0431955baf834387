// The CLI's OpenEXR files hold colour always and each pass the result has:
// Depth (Z) without Normal when only Depth was resolved (RenderSettings::
// normal_pass off), both when both were, neither when the passes are off.
#include <gtest/gtest.h>
#include <unistd.h>

#include <ImfArray.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <cstdio>
#include <set>
#include <string>

#include "io/image_io.h"
#include "micropoly/render_result.h"

namespace {

std::set<std::string> channels(const std::string& path) {
  Imf::InputFile in(path.c_str());
  std::set<std::string> names;
  for (auto c = in.header().channels().begin(); c != in.header().channels().end(); ++c) names.insert(c.name());
  return names;
}

mp::RenderResult result(bool depth, bool normal) {
  mp::RenderResult r;
  r.width = 4, r.height = 3;
  r.rgba.assign(4 * 12, 0.25f);
  if (depth)
    for (int i = 0; i < 12; ++i) r.depth.push_back(1.5f + float(i));
  if (normal) r.normal.assign(3 * 12, 0.5f);
  return r;
}

TEST(ExrPasses, EachPassTheResultHasAndNoOther) {
  const std::string path = ::testing::TempDir() + "/exr_passes_" + std::to_string(::getpid()) + ".exr";
  const std::set<std::string> colour{"R", "G", "B", "A"}, normal{"N.X", "N.Y", "N.Z"};
  auto with = [](std::set<std::string> a, const std::set<std::string>& b) {
    a.insert(b.begin(), b.end());
    return a;
  };
  mp::write_image(path, result(false, false));
  EXPECT_EQ(channels(path), colour);
  mp::write_image(path, result(true, false));
  EXPECT_EQ(channels(path), with(colour, {"Z"}));
  mp::write_image(path, result(true, true));
  EXPECT_EQ(channels(path), with(with(colour, {"Z"}), normal));

  // Depth as written, pixel for pixel.
  mp::write_image(path, result(true, false));
  Imf::InputFile in(path.c_str());
  Imf::Array2D<float> z(3, 4);
  Imf::FrameBuffer fb;
  fb.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(&z[0][0]), sizeof(float), 4 * sizeof(float)));
  in.setFrameBuffer(fb);
  in.readPixels(0, 2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(z[y][x], 1.5f + float(y * 4 + x));
  std::remove(path.c_str());
}

}  // namespace
