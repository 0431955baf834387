// Material programs (kernels/materials/material_program.cl): node functions
// from source text, run by the pipeline, checked against analytic results,
// and bad programs or references rejected with the material's name.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

class MaterialProgramTest : public SharedRendererTest {};

const char* kNoSurface = "void mp_node_surface(const MpNodeGlobals* g, MpSurfaceInputs* s) {}\n";
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

TEST_F(MaterialProgramTest, ConstantDisplacementMovesThePlaneAlongItsNormal) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Matte));
  s.material_programs.push_back(
      {"lift", std::string("float3 mp_node_displacement(const MpNodeGlobals* g) { return 0.5f * g->N; }\n") +
                   kNoSurface});
  s.materials[0].program_displaces = true;
  s.materials[0].displacement_bound = 0.5f;
  RenderResult r = renderer_->render(s);
  const size_t centre = 32 * 64 + 32;
  EXPECT_NEAR(r.depth[centre], 4.5f, 1e-3f);  // 0.5 nearer than the undisplaced plane at 5
  EXPECT_NEAR(r.normal[3 * centre + 2], 1.0f, 1e-3f);  // normals from the displaced grid: still +Z
}

TEST_F(MaterialProgramTest, SurfaceProgramColorsByGeneratedCoordinates) {
  Scene s = facing_plane(static_cast<int>(Material::Model::Constant));
  s.material_programs.push_back(
      {"ramp", std::string(kNoDisplacement) +
                   "void mp_node_surface(const MpNodeGlobals* g, MpSurfaceInputs* s) {"
                   " s->base_color = (float3)(g->generated.x, 0.0f, 0.0f); }\n"});
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
