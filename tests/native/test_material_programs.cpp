// Material programs (kernels/materials/material_program.cl): node functions
// from source text, run by the pipeline, checked against analytic results,
// and bad programs or references rejected with the material's name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <sstream>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "renderer_fixture.h"
#include "scene/curves.h"
#include "core/mp_compat.h"
#include "materials/mp_surface_record.h"
#include "pipeline/materials/material_programs.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class MaterialProgramTest : public SharedRendererTest {};

const char* kNoSurface = "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n";
const char* kNoDisplacement = "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }\n";

// A 6 x 6 plane at z = 0 facing a camera at z = 5 (45 degree field of view).
Scene facing_plane(int program_material_model) {
  Scene s = base_scene(64, 64, 4);
  s.camera = look_at({0, 0, 5}, {0, 0, 0});
  s.meshes.push_back(polygon({{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}}));
  s.materials[0].model = static_cast<Material::Model>(program_material_model);
  s.materials[0].name = "node material";
  s.materials[0].program = 0;
  return s;
}

// The plane displaced by a constant 0.5 along its normal.
Scene lifted_plane() {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));
  s.material_programs.push_back(
      {"lift", std::string("float3 mp_node_displacement(const MpNodeGlobals* g) { return 0.5f * g->N; }\n") +
                   kNoSurface});
  s.materials[0].program_displaces = true;
  s.materials[0].displacement_bound = 0.5f;
  return s;
}

TEST_F(MaterialProgramTest, ConstantDisplacementMovesThePlaneAlongItsNormal) {
  Scene s = lifted_plane();
  RenderResult r = renderer_->render(s);
  const size_t centre = 32 * 64 + 32;
  EXPECT_NEAR(r.depth[centre], 4.5f, 1e-3f);  // 0.5 nearer than the undisplaced plane at 5
  EXPECT_NEAR(r.normal[3 * centre + 2], 1.0f, 1e-3f);  // normals from the displaced grid: still +Z
}

TEST_F(MaterialProgramTest, SurfaceProgramColorsByGeneratedCoordinates) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.material_programs.push_back(
      {"ramp", std::string(kNoDisplacement) +
                   "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                   " mp_add_emission(s, (float3)(g->generated.x, 0.0f, 0.0f)); }\n"});
  s.materials[0].program_shades = true;
  RenderResult r = renderer_->render(s);
  // Generated x = (x + 3) / 6 across the plane's texture space (its bounding
  // box); pixel column c sees x = 5 tan(22.5 deg) ((c + 0.5) / 32 - 1).
  const float half = 5.0f * std::tan(glm::radians(22.5f));
  for (int c : {8, 16, 32, 48, 56}) {
    const float x = half * ((c + 0.5f) / 32.0f - 1.0f);
    EXPECT_NEAR(r.rgba[4 * (32 * 64 + c)], (x + 3.0f) / 6.0f, 2e-3f) << "column " << c;
  }
}

// UVs that are an affine function of position reach the program unchanged
// wherever the surface is that same affine image of its faces: a flat n-gon
// (split into quads around its centroid) and the interior of a uniform
// Catmull-Clark grid, whose limit surface reproduces linear functions (UVs
// pass through OpenSubdiv's face-varying patches there).
glm::vec2 affine_uv(glm::vec3 p) { return {0.1f * p.x + 0.3f, 0.05f * p.y + 0.02f * p.x + 0.2f}; }

void set_affine_uvs(Mesh& m) {
  std::vector<glm::vec2> layer;
  for (int v : m.face_vertex_indices) layer.push_back(affine_uv(m.points[size_t(v)]));
  m.uv_layers = {std::vector<glm::vec2>(layer.size(), glm::vec2(7.0f)), layer};  // layer 1 is read
}

void expect_affine_uv_colours(const RenderResult& r, const char* what) {
  const float half = 5.0f * std::tan(glm::radians(22.5f));
  for (int row : {10, 32, 50})
    for (int c : {8, 20, 32, 44, 56}) {
      const glm::vec3 p(half * ((c + 0.5f) / 32.0f - 1.0f), -half * ((row + 0.5f) / 32.0f - 1.0f), 0.0f);
      const glm::vec2 uv = affine_uv(p);
      const size_t px = 4 * (size_t(row) * 64 + size_t(c));
      EXPECT_NEAR(r.rgba[px], uv.x, 2e-3f) << what << " row " << row << " column " << c;
      EXPECT_NEAR(r.rgba[px + 1], uv.y, 2e-3f) << what << " row " << row << " column " << c;
    }
}

TEST_F(MaterialProgramTest, SurfaceProgramReadsUVLayers) {
  const std::string program = std::string(kNoDisplacement) +
                              "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                              " mp_add_emission(s, (float3)(g->uv[1].x, g->uv[1].y, 0.0f)); }\n";
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.meshes[0] = polygon({{-4, -3, 0}, {3, -4, 0}, {5, 1, 0}, {0, 4, 0}, {-5, 2, 0}});
  set_affine_uvs(s.meshes[0]);
  s.material_programs.push_back({"uv", program});
  s.materials[0].program_shades = true;
  expect_affine_uv_colours(renderer_->render(s), "pentagon");

  s.meshes[0] = grid_mesh(12, 6.0f, SubdivScheme::CatmullClark);
  set_affine_uvs(s.meshes[0]);
  expect_affine_uv_colours(renderer_->render(s), "subdivided grid");
}

// A curve's per-point values (CurveSet::point_layers) reach the program
// blended linearly along it, on every piece the tube's bends cut a segment
// into: a zig-zag towards the camera whose keys are evenly spaced in x
// carries x itself, which a Catmull-Rom curve reproduces exactly in its
// inner segments, so the value read is the point's x to within the tube's
// radius.
TEST_F(MaterialProgramTest, CurvePointValuesFollowTheCurve) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.meshes.clear();
  s.settings.width = s.settings.height = 160;
  s.material_programs.push_back({"along", std::string(kNoDisplacement) +
                                              "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                              " mp_add_emission(s, (float3)(g->uv[0].x, (g->P.x + 2.0f) / 4.0f,"
                                              " g->uv[0].y)); }\n"});
  s.materials[0].program_shades = true;
  CurveSet curves;
  curves.name = "zig-zag";
  curves.point_layers.resize(1);
  for (int k = 0; k <= 8; ++k) {
    const float x = -2.0f + 0.5f * float(k);
    curves.points.emplace_back(x, 0.3f * float(k % 3) - 0.3f, k % 2 ? 0.5f : -0.5f);
    curves.radii.push_back(0.08f);
    curves.point_layers[0].emplace_back((x + 2.0f) / 4.0f, 0.25f);
  }
  curves.offsets = {0, 9};
  ASSERT_EQ(add_curves(s, curves), 0u);
  ASSERT_EQ(s.bezier_patches.size(), 1u);
  const BezierPatches& set = s.bezier_patches[0];
  ASSERT_EQ(set.uv_layers.size(), 1u);
  EXPECT_EQ(set.uv_layers[0].size(), set.control_points.size() / 4);
  EXPECT_GT(set.control_points.size() / 16, size_t(8 * kTubePatchesPerSegment)) << "the bends cut no segment";
  // Each ring's centre (the mean of its four quarters' first points) is on
  // the curve: in the inner segments its x is what the value says.
  for (size_t p = 0; p + kTubePatchesPerSegment <= set.control_points.size() / 16; p += kTubePatchesPerSegment)
    for (int row : {0, 3}) {
      glm::vec3 centre(0.0f);
      for (int q = 0; q < kTubePatchesPerSegment; ++q) centre += set.control_points[16 * (p + q) + 4 * row] / 4.0f;
      if (std::fabs(centre.x) > 1.45f) continue;
      for (int q = 0; q < kTubePatchesPerSegment; ++q)
        for (int corner : {0, 1}) {
          const float value = set.uv_layers[0][4 * (p + q) + (row ? 2 : 0) + corner].x;
          EXPECT_NEAR(value, (centre.x + 2.0f) / 4.0f, 1e-5f) << "patch " << p + q << " row " << row;
        }
    }
  const RenderResult r = renderer_->render(s);
  double error = 0.0, worst = 0.0;
  int covered = 0;
  for (size_t px = 0; px < r.rgba.size(); px += 4) {
    if (r.rgba[px + 3] < 0.999f || r.rgba[px + 1] < 0.2f || r.rgba[px + 1] > 0.8f) continue;  // inner segments
    const double e = std::fabs(double(r.rgba[px]) - double(r.rgba[px + 1]));
    error += e, worst = std::max(worst, e), ++covered;
    EXPECT_NEAR(r.rgba[px + 2], 0.25f, 1e-4f);
  }
  // A surface point is at most the radius from the centre line in x: 0.08
  // over the 4 units the values span. A piece given another piece's values
  // would be off by up to a segment's 0.125.
  ASSERT_GT(covered, 100);
  EXPECT_LT(worst, 0.08 / 4.0 + 0.003) << covered << " pixels";
  EXPECT_LT(error / covered, 0.015);

  // Written to RIB (each Patch with its corner values) and read back.
  std::ostringstream written;
  write_rib(s, written);
  const RibResult back = read_rib_string(written.str(), "curves.rib");
  ASSERT_EQ(back.scene.bezier_patches.size(), 1u);
  EXPECT_EQ(back.scene.bezier_patches[0].uv_layers, set.uv_layers);
  const RenderResult again = renderer_->render(back.scene);
  EXPECT_EQ(again.rgba, r.rgba);
}

// RIB carries material programs (Attribute "micropoly" "string program"):
// the scene read back renders the same displaced plane.
TEST_F(MaterialProgramTest, ProgramsSurviveARibRoundTrip) {
  Scene s = lifted_plane();
  std::ostringstream rib;
  write_rib(s, rib);
  Scene back = read_rib_string(rib.str(), "roundtrip").scene;
  ASSERT_EQ(back.material_programs.size(), 1u);
  EXPECT_EQ(back.material_programs[0].source, s.material_programs[0].source);
  ASSERT_FALSE(back.materials.empty());
  EXPECT_EQ(back.materials[0].program, 0);
  EXPECT_TRUE(back.materials[0].program_displaces);
  EXPECT_FLOAT_EQ(back.materials[0].displacement_bound, 0.5f);
  RenderResult r = renderer_->render(back);
  EXPECT_NEAR(r.depth[32 * 64 + 32], 4.5f, 1e-3f);
}

// Image Texture lookups from a program: a 2 x 1 image (black | white, sRGB
// encoded) under Linear / Extend across the plane's U, and a missing image
// index, which renders magenta.
TEST_F(MaterialProgramTest, ImagesAreFilteredThenDecodedAndMissingOnesAreMagenta) {
  const std::string lookup =
      "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
      " float4 c = mp_tex_image(g->images, g->image_count, g->texels, INDEX, g->uv[0].x, 0.5f, 0, 1);"
      " mp_add_emission(s, c.xyz); }\n";
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  std::vector<glm::vec2> uvs;
  for (int v : s.meshes[0].face_vertex_indices) uvs.push_back((glm::vec2(s.meshes[0].points[size_t(v)]) + 3.0f) / 6.0f);
  s.meshes[0].uv_layers = {uvs};
  s.images.push_back({"ramp", 2, 1, {glm::vec4(0.0f, 0.0f, 0.0f, 1.0f), glm::vec4(1.0f)}, true});
  auto with_index = [&](const char* index) {
    std::string src = lookup;
    src.replace(src.find("INDEX"), 5, index);
    return std::string("#include \"textures/mp_tex_image.h\"\n") + kNoDisplacement + src;
  };
  s.material_programs.push_back({"image", with_index("0")});
  s.materials[0].program_shades = true;
  RenderResult r = renderer_->render(s);
  // u = (x + 3) / 6; texel centres at u = 1/4 and 3/4, Extend beyond them.
  // The sRGB value blends linearly in u, then decodes.
  const float half = 5.0f * std::tan(glm::radians(22.5f));
  auto srgb_to_linear = [](float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); };
  // The pixel may sit up to a quarter pixel off (sampling and filtering),
  // so the value must lie in the ramp's range over that span.
  auto expected = [&](float column) {
    const float u = (half * (column / 32.0f - 1.0f) + 3.0f) / 6.0f;
    return srgb_to_linear(std::clamp((u - 0.25f) * 2.0f, 0.0f, 1.0f));
  };
  for (int c : {16, 28, 32, 36, 48}) {
    const float lo = expected(c + 0.25f) - 1e-3f, hi = expected(c + 0.75f) + 1e-3f;
    const float got = r.rgba[4 * (32 * 64 + c)];
    EXPECT_TRUE(got >= lo && got <= hi) << "column " << c << ": " << got << " not in [" << lo << ", " << hi << "]";
  }
  s.material_programs[0].source = with_index("5");
  r = renderer_->render(s);
  EXPECT_NEAR(r.rgba[4 * (32 * 64 + 32)], 1.0f, 1e-5f);
  EXPECT_NEAR(r.rgba[4 * (32 * 64 + 32) + 1], 0.0f, 1e-5f);
  EXPECT_NEAR(r.rgba[4 * (32 * 64 + 32) + 2], 1.0f, 1e-5f);
}

TEST_F(MaterialProgramTest, ImagesWithoutTheirPixelsOrWithNaNsAreRejected) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));
  s.material_programs.push_back({"ok", std::string(kNoDisplacement) + kNoSurface});
  s.images.push_back({"short", 2, 2, std::vector<glm::vec4>(3, glm::vec4(0.5f)), false});
  try {
    validate_scene(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("short"), std::string::npos) << e.what();
  }
  s.images[0] = {"nan", 1, 1, {glm::vec4(std::nanf(""))}, false};
  EXPECT_THROW(validate_scene(s), Error);
}

TEST_F(MaterialProgramTest, NegativeDisplacementBoundInRibIsAnError) {
  const std::string rib =
      "WorldBegin\nAttribute \"micropoly\" \"integer material\" [0] \"string program\" [\"x\"] "
      "\"float displacementbound\" [-1]\nWorldEnd\n";
  EXPECT_THROW(read_rib_string(rib, "bad bound"), Error);
}

TEST_F(MaterialProgramTest, UVMapsOfTheWrongSizeAreRejected) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));
  s.material_programs.push_back({"ok", std::string(kNoDisplacement) + kNoSurface});
  s.meshes[0].uv_layers = {std::vector<glm::vec2>(3)};
  EXPECT_THROW(validate_scene(s), Error);
  s.meshes[0].uv_layers = {std::vector<glm::vec2>(4, glm::vec2(std::nanf(""), 0.0f))};
  EXPECT_THROW(validate_scene(s), Error);
}

TEST_F(MaterialProgramTest, ProgramThatDoesNotCompileNamesTheMaterial) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));
  s.material_programs.push_back({"node material", "this is not OpenCL C"});
  s.materials[0].program_shades = true;
  try {
    renderer_->render(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("material 'node material'"), std::string::npos) << e.what();
  }
}

// A tree whose structure changes from frame to frame builds a program per
// frame: the renderer keeps those the scene uses and a few spare
// (MaterialPrograms::kSparePrograms), not every one it ever built.
TEST_F(MaterialProgramTest, ProgramsNoLongerUsedAreReleasedBeyondAFewSpare) {
  auto emitting = [](int value) {
    Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
    s.material_programs.push_back(
        {"animated", std::string(kNoDisplacement) + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                                    " mp_add_emission(s, (float3)(" + std::to_string(value) +
                         ".0f / 64.0f)); }\n"});
    s.materials[0].program_shades = true;
    return s;
  };
  renderer_->render(emitting(0));
  EXPECT_EQ(renderer_->render(emitting(0)).stats.program_build_ms, 0.0) << "held programs are not rebuilt";
  for (int v = 1; v <= 8; ++v) renderer_->render(emitting(v));  // 8 others: program 0 is still a spare
  EXPECT_EQ(renderer_->render(emitting(0)).stats.program_build_ms, 0.0);
  for (int v = 1; v <= 9; ++v) renderer_->render(emitting(v));  // 9 others: program 0 is the oldest spare
  RenderResult r = renderer_->render(emitting(0));
  EXPECT_GT(r.stats.program_build_ms, 0.0) << "the least recently used program is released";
  EXPECT_NEAR(r.rgba[4 * (32 * 64 + 32)], 0.0f, 1e-6f);
  EXPECT_NEAR(renderer_->render(emitting(9)).rgba[4 * (32 * 64 + 32)], 9.0f / 64.0f, 1e-5f);
}

// Node values travel beside the program (Material::program_params, read by
// MP_PARAM): two materials share one program and each shows its own
// values; new values render without a build; RIB carries them.
TEST_F(MaterialProgramTest, MaterialsSharingAProgramReadTheirOwnNodeValues) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.meshes[0] = polygon({{-3, -3, 0}, {-0.5f, -3, 0}, {-0.5f, 3, 0}, {-3, 3, 0}});
  s.meshes.push_back(polygon({{0.5f, -3, 0}, {3, -3, 0}, {3, 3, 0}, {0.5f, 3, 0}}));
  s.meshes[1].material = 1;
  s.materials.push_back(s.materials[0]);
  s.materials[1].name = "second";
  s.material_programs.push_back(
      {"values", std::string(kNoDisplacement) + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                                " mp_add_emission(s, MP_PARAM3(1) * MP_PARAM(0)); }\n"});
  s.materials[0].program_shades = s.materials[1].program_shades = true;
  s.materials[0].program_params = {2.0f, 0.1f, 0.2f, 0.3f};
  s.materials[1].program_params = {0.5f, 1.2f, 0.8f, 0.4f};
  auto expect_colours = [](const RenderResult& r, glm::vec3 left, glm::vec3 right, const char* what) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(r.rgba[4 * (32 * 64 + 12) + c], left[c], 1e-5f) << what << " left, channel " << c;
      EXPECT_NEAR(r.rgba[4 * (32 * 64 + 52) + c], right[c], 1e-5f) << what << " right, channel " << c;
    }
  };
  RenderResult first = renderer_->render(s);
  expect_colours(first, {0.2f, 0.4f, 0.6f}, {0.6f, 0.4f, 0.2f}, "first render");

  s.materials[0].program_params = {1.0f, 0.9f, 0.0f, 0.5f};
  RenderResult edited = renderer_->render(s);
  EXPECT_EQ(edited.stats.program_build_ms, 0.0) << "new values need no new program";
  expect_colours(edited, {0.9f, 0.0f, 0.5f}, {0.6f, 0.4f, 0.2f}, "edited");

  std::ostringstream rib;
  write_rib(s, rib);
  Scene back = read_rib_string(rib.str(), "roundtrip").scene;
  ASSERT_EQ(back.material_programs.size(), 1u);
  ASSERT_EQ(back.materials.size(), 2u);
  EXPECT_EQ(back.materials[0].program_params, s.materials[0].program_params);
  EXPECT_EQ(back.materials[1].program_params, s.materials[1].program_params);
  expect_colours(renderer_->render(back), {0.9f, 0.0f, 0.5f}, {0.6f, 0.4f, 0.2f}, "read back from RIB");
}

// Programs shade a range of the batch's vertices at a time through the
// record pool (kernels/materials/mp_surface_record.h): two programs on two
// halves of a frame whose batch holds many ranges, each program's vertices
// lit by it alone, every pixel checked against the analytic colour, and the
// pool within its budget.
TEST_F(MaterialProgramTest, TwoProgramsOverManyRecordRangesLightOnlyTheirOwnVertices) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.settings.width = s.settings.height = 384;
  set_samples_per_pixel(s.settings, 1);
  s.meshes[0] = polygon({{-3, -3, 0}, {0, -3, 0}, {0, 3, 0}, {-3, 3, 0}});
  s.meshes.push_back(polygon({{0, -3, 0}, {3, -3, 0}, {3, 3, 0}, {0, 3, 0}}));
  s.meshes[1].material = 1;
  s.materials.push_back(s.materials[0]);
  s.materials[1].name = "right";
  s.materials[1].program = 1;
  s.material_programs.push_back(
      {"red by x", std::string(kNoDisplacement) + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                                  " mp_add_emission(s, (float3)(g->generated.x, 0.0f, 0.0f)); }\n"});
  s.material_programs.push_back(
      {"green by y", std::string(kNoDisplacement) + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                                    " mp_add_emission(s, (float3)(0.0f, g->generated.y, 0.0f)); }\n"});
  s.materials[0].program_shades = s.materials[1].program_shades = true;
  RenderResult r = renderer_->render(s);
  ASSERT_EQ(r.width, 384);
  // Generated coordinates span each half's own box: x over [-3, 0] on the
  // left, y over [-3, 3] on the right.
  const float half = 5.0f * std::tan(glm::radians(22.5f));
  int checked = 0;
  for (int row = 2; row < 384; row += 7)
    for (int c = 2; c < 384; c += 7) {
      const float x = half * ((c + 0.5f) / 192.0f - 1.0f), y = -half * ((row + 0.5f) / 192.0f - 1.0f);
      if (std::fabs(x) < 0.05f) continue;  // pixels the seam between the halves covers
      const float* px = &r.rgba[4 * (size_t(row) * 384 + size_t(c))];
      const glm::vec3 want = x < 0.0f ? glm::vec3((x + 3.0f) / 3.0f, 0.0f, 0.0f)
                                      : glm::vec3(0.0f, (y + 3.0f) / 6.0f, 0.0f);
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(px[k], want[k], 4e-3f) << "row " << row << " column " << c;
      ++checked;
    }
  EXPECT_GT(checked, 2500);
  // More vertices than one range holds (32 MiB of 928-byte records on a
  // CPU, 256 MiB on a GPU), yet the pool never beyond its budget.
  EXPECT_GT(r.stats.micropolygons, size_t(MaterialPrograms::kRecordPoolMiB << 20) / MP_SURFACE_RECORD_BYTES);
  EXPECT_GT(r.stats.surface_record_bytes, 0u);
  EXPECT_LE(r.stats.surface_record_bytes, size_t(MaterialPrograms::kRecordPoolGpuMiB) << 20);
}

// A curve's samples travel as node values too (MP_PARAM_TABLE, read by the
// _p lookups of kernels/textures/mp_tex_color.h): a moved curve point
// renders with no build, and a table shorter than the program reads is
// refused.
TEST_F(MaterialProgramTest, CurveTablesAreNodeValues) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.material_programs.push_back(
      {"curve", "#include \"textures/mp_tex_color.h\"\n" + std::string(kNoDisplacement) +
                    "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                    " float v = mp_curve_float_p(MP_PARAM_TABLE(2, 3), 3, MP_PARAM(0), MP_PARAM(1), 0, 1.0f, 0.75f);"
                    " mp_add_emission(s, (float3)(v)); }\n"});
  s.materials[0].program_shades = true;
  // Samples 0, 0.2, 1 over [0.5, 1]: 0.75 is the middle sample.
  s.materials[0].program_params = {0.5f, 1.0f, 0.0f, 0.2f, 1.0f};
  const size_t centre = 4 * (32 * 64 + 32);
  EXPECT_NEAR(renderer_->render(s).rgba[centre], 0.2f, 1e-5f);
  s.materials[0].program_params[3] = 0.6f;
  const RenderResult moved = renderer_->render(s);
  EXPECT_EQ(moved.stats.program_build_ms, 0.0) << "a moved curve point needs no new program";
  EXPECT_NEAR(moved.rgba[centre], 0.6f, 1e-5f);
  // Over [0, 1] instead, 0.75 lies between the last two samples.
  s.materials[0].program_params[0] = 0.0f;
  EXPECT_NEAR(renderer_->render(s).rgba[centre], 0.8f, 1e-5f);
  s.materials[0].program_params.pop_back();
  try {
    validate_scene(s);
    FAIL() << "expected an error for 4 values of 5";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("its program reads 5 node values, but it has 4"), std::string::npos)
        << e.what();
  }
}

// A program that reads more node values than its material has, or values
// that are not finite, are refused before anything reaches the device.
TEST_F(MaterialProgramTest, MissingOrNonFiniteNodeValuesAreRejected) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.material_programs.push_back(
      {"values", std::string(kNoDisplacement) + "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                                " mp_add_emission(s, MP_PARAM(1) * MP_PARAM4(2).xyz); }\n"});
  s.materials[0].program_shades = true;
  s.materials[0].program_params = {0, 0, 0, 0, 0};
  try {
    validate_scene(s);
    FAIL() << "expected an error for 5 values of 6";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'node material': its program reads 6 node values, but it has 5"),
              std::string::npos) << e.what();
  }
  s.materials[0].program_params.push_back(1.0f);
  validate_scene(s);
  s.materials[0].program_params[3] = std::nanf("");
  EXPECT_THROW(validate_scene(s), Error);
  s.materials[0].program_params[3] = 0.0f;
  // Written by hand, with blanks: still counted (8 and 10 values).
  for (const char* read : {"MP_PARAM ( 7 )", "MP_PARAM_TABLE( 4 ,6)[0]"}) {
    Scene spaced = s;
    spaced.material_programs[0].source = std::string(kNoDisplacement) +
                                         "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {"
                                         " mp_add_emission(s, (float3)(" + read + ")); }\n";
    EXPECT_THROW(validate_scene(spaced), Error) << read;
  }
  s.world.program = 0;  // the world reads the same six values of its own
  s.world.program_params = {1, 2, 3};
  EXPECT_THROW(validate_scene(s), Error);
}

TEST_F(MaterialProgramTest, BadProgramReferencesAndBoundsAreRejected) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));  // program 0 of none
  EXPECT_THROW(validate_scene(s), Error);
  s.material_programs.push_back({"ok", std::string(kNoDisplacement) + kNoSurface});
  validate_scene(s);
  for (float bound : {-1.0f, std::nanf("")}) {
    s.materials[0].displacement_bound = bound;
    try {
      validate_scene(s);
      FAIL() << "expected an error for bound " << bound;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("node material"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mp::test
