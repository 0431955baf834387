// RIB reader: requests into Scene values, transformations (order and
// RenderMan's row-vector convention), camera conversion, orientation,
// lights, materials, archives, instancing and subdivision tags.
// Patches are tested in test_rib_patches.cpp, malformed input in
// test_rib_errors.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>

#include "rib/rib_reader.h"

namespace {

const std::string kScenes = MICROPOLY_TEST_SCENES;

mp::RibResult parse(const std::string& text) {
  return mp::read_rib_string(text, "test.rib", kScenes);
}

// A world block around `body`, with the camera at the origin.
mp::RibResult parse_world(const std::string& body) {
  return parse("WorldBegin\n" + body + "\nWorldEnd\n");
}

const mp::Mesh* find_mesh(const mp::Scene& scene, const std::string& name, int nth = 0) {
  for (const mp::Mesh& m : scene.meshes)
    if (m.name == name && nth-- == 0) return &m;
  return nullptr;
}

int count_warnings(const mp::RibResult& r, const std::string& fragment) {
  int n = 0;
  for (const std::string& w : r.warnings) n += w.find(fragment) != std::string::npos;
  return n;
}

glm::vec3 apply(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

void expect_near(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps) << "x";
  EXPECT_NEAR(a.y, b.y, eps) << "y";
  EXPECT_NEAR(a.z, b.z, eps) << "z";
}

// The front normal of a face in Micropoly camera space, per scene.h: the
// right-hand-rule normal of the counter-clockwise face in object space,
// carried to camera space as a normal (so mirroring keeps the front side).
glm::vec3 front_normal_in_camera(const mp::Scene& scene, const mp::Mesh& mesh, int face) {
  int offset = 0;
  for (int f = 0; f < face; ++f) offset += mesh.face_vertex_counts[static_cast<size_t>(f)];
  const auto& idx = mesh.face_vertex_indices;
  const glm::vec3 a = mesh.points[static_cast<size_t>(idx[static_cast<size_t>(offset)])];
  const glm::vec3 b = mesh.points[static_cast<size_t>(idx[static_cast<size_t>(offset + 1)])];
  const glm::vec3 c = mesh.points[static_cast<size_t>(idx[static_cast<size_t>(offset + 2)])];
  const glm::mat4 to_camera = scene.camera.world_to_camera * mesh.object_to_world;
  return glm::inverseTranspose(glm::mat3(to_camera)) * glm::cross(b - a, c - a);
}

// True if the face's front side faces the camera at the origin.
bool faces_camera(const mp::Scene& scene, const mp::Mesh& mesh, int face) {
  const glm::mat4 to_camera = scene.camera.world_to_camera * mesh.object_to_world;
  const glm::vec3 p = apply(to_camera, mesh.points[static_cast<size_t>(mesh.face_vertex_indices[0])]);
  return glm::dot(front_normal_in_camera(scene, mesh, face), -p) > 0.0f;
}

// --- defaults ---------------------------------------------------------------------

TEST(RibDefaults, RenderManDefaultsAreSetExplicitly) {
  const mp::RibResult r = parse_world("");
  const mp::Scene& s = r.scene;
  EXPECT_EQ(s.settings.width, 640);
  EXPECT_EQ(s.settings.height, 480);
  EXPECT_FLOAT_EQ(s.settings.pixel_aspect, 1.0f);
  EXPECT_EQ(s.settings.samples_x, 2);
  EXPECT_EQ(s.settings.samples_y, 2);
  EXPECT_EQ(s.settings.filter, mp::PixelFilter::Gaussian);
  EXPECT_FLOAT_EQ(s.settings.filter_width, 2.0f);
  EXPECT_FLOAT_EQ(s.settings.shading_rate, 1.0f);
  EXPECT_EQ(s.camera.projection, mp::Camera::Projection::Perspective);
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 90.0f);
  EXPECT_EQ(s.camera.screen_left, s.camera.screen_right);  // derived from the aspect ratio
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].model, mp::Material::Model::Matte);
  EXPECT_EQ(s.materials[0].color, glm::vec3(1.0f));
  EXPECT_FLOAT_EQ(s.materials[0].kd, 1.0f);
  EXPECT_TRUE(r.display_name.empty());
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RibDefaults, DefaultStateUsesMaterialZeroAndTwoSides) {
  const mp::RibResult r = parse_world("Polygon \"P\" [0 0 1 1 0 1 0 1 1]");
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  EXPECT_EQ(r.scene.meshes[0].material, 0);
  EXPECT_TRUE(r.scene.meshes[0].double_sided);
  EXPECT_EQ(r.scene.meshes[0].scheme, mp::SubdivScheme::None);
}

// --- transformations ----------------------------------------------------------------

TEST(RibTransform, LastTransformAppliesFirst) {
  // Translate then Scale: the point is scaled first, then translated.
  mp::RibResult r = parse_world("Translate 1 0 0\nScale 2 2 2\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {3, 0, 0});
  // Scale then Translate: translated first, then scaled.
  r = parse_world("Scale 2 2 2\nTranslate 1 0 0\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {4, 0, 0});
}

TEST(RibTransform, RotateFollowsTheAxisRule) {
  mp::RibResult r = parse_world("Rotate 90 0 0 1\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {0, 1, 0});
  r = parse_world("Rotate 90 1 0 0\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {0, 1, 0}), {0, 0, 1});
  // Rotation after translation in the file: rotate the point, then translate.
  r = parse_world("Translate 0 0 5\nRotate 90 0 1 0\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {0, 0, 4});
}

TEST(RibTransform, MatricesAreRowVectorRowMajor) {
  // RenderMan writes the translation in elements 12..14 (row-vector matrices).
  mp::RibResult r = parse_world(
      "ConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 1, 1}), {6, 7, 8});
  // A non-symmetric linear part: row 0 is the image of the x axis.
  r = parse_world("ConcatTransform [0 1 0 0  -1 0 0 0  0 0 1 0  0 0 0 1]\n"
                  "Polygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {0, 1, 0});
  // ConcatTransform composes like Translate/Scale: new matrices apply first.
  r = parse_world("Translate 1 0 0\nConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1]\n"
                  "Polygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {1, 0, 0}), {3, 0, 0});
  // Transform replaces the current transformation.
  r = parse_world("Translate 9 9 9\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  1 2 3 1]\n"
                  "Polygon \"P\" [0 0 0 1 0 0 0 1 0]");
  expect_near(apply(r.scene.meshes[0].object_to_world, {0, 0, 0}), {1, 2, 3});
}

TEST(RibTransform, BlocksRestoreState) {
  const mp::RibResult r = parse_world(
      "Translate 1 0 0\n"
      "TransformBegin\n Translate 0 1 0\n Color [1 0 0]\nTransformEnd\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"       // color kept (TransformEnd restores only the CTM)
      "AttributeBegin\n Translate 0 0 1\n Color [0 0 1]\nAttributeEnd\n"
      "Translate 0 0 0.5\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  ASSERT_EQ(r.scene.meshes.size(), 2u);
  expect_near(apply(r.scene.meshes[0].object_to_world, {0, 0, 0}), {1, 0, 0});
  expect_near(apply(r.scene.meshes[1].object_to_world, {0, 0, 0}), {1, 0, 0.5f});
  EXPECT_EQ(r.scene.materials[static_cast<size_t>(r.scene.meshes[0].material)].color, glm::vec3(1, 0, 0));
  EXPECT_EQ(r.scene.materials[static_cast<size_t>(r.scene.meshes[1].material)].color, glm::vec3(1, 0, 0));
}

// --- camera -----------------------------------------------------------------------------

TEST(RibCamera, LeftHandedCameraBecomesRightHandedLookingDownMinusZ) {
  const mp::RibResult r = parse(
      "Projection \"perspective\" \"fov\" 40\nTranslate 0 0 5\nWorldBegin\nWorldEnd\n");
  const mp::Camera& cam = r.scene.camera;
  EXPECT_FLOAT_EQ(cam.fov_degrees, 40.0f);
  // The world origin is 5 units in front of the camera: -5 in Micropoly.
  expect_near(apply(cam.world_to_camera, {0, 0, 0}), {0, 0, -5});
  // x stays right and y stays up.
  expect_near(apply(cam.world_to_camera, {1, 2, 0}), {1, 2, -5});
  // Farther from the camera in RenderMan (+z) is more negative z here.
  expect_near(apply(cam.world_to_camera, {0, 0, 1}), {0, 0, -6});
}

TEST(RibCamera, CameraTransformOrder) {
  // Rotate 90 about y after moving the world 5 ahead: a world point on +x
  // ends up on the view axis.
  const mp::RibResult r = parse("Translate 0 0 5\nRotate -90 0 1 0\nWorldBegin\nWorldEnd\n");
  // Rotate -90 about y maps +x to +z (in front), then the translation.
  expect_near(apply(r.scene.camera.world_to_camera, {1, 0, 0}), {0, 0, -6});
}

TEST(RibCamera, DepthOfFieldIsAThinLens) {
  // Radius = focallength / (2 fstop), as RenderMan; the shape from Option "micropoly".
  const mp::RibResult r = parse(
      "Option \"micropoly\" \"integer apertureblades\" 6 \"float aperturerotation\" 0.5 \"float apertureratio\" 2\n"
      "Projection \"perspective\" \"fov\" 40\nDepthOfField 2.8 0.05 3.5\nWorldBegin\nWorldEnd\n");
  const mp::Camera& cam = r.scene.camera;
  EXPECT_FLOAT_EQ(cam.lens_radius, 0.05f / 5.6f);
  EXPECT_FLOAT_EQ(cam.focus_distance, 3.5f);
  EXPECT_EQ(cam.aperture_blades, 6);
  EXPECT_FLOAT_EQ(cam.aperture_rotation, 0.5f);
  EXPECT_FLOAT_EQ(cam.aperture_ratio, 2.0f);
  // No arguments: a pinhole again.
  EXPECT_EQ(parse("DepthOfField 2.8 0.05 3.5\nDepthOfField\nWorldBegin\nWorldEnd\n").scene.camera.lens_radius, 0.0f);
}

TEST(RibCamera, ProjectionScreenWindowClipping) {
  mp::RibResult r = parse(
      "Projection \"orthographic\"\nScreenWindow -2 2 -1 1\nClipping 0.5 20\nWorldBegin\nWorldEnd\n");
  const mp::Camera& cam = r.scene.camera;
  EXPECT_EQ(cam.projection, mp::Camera::Projection::Orthographic);
  EXPECT_FLOAT_EQ(cam.screen_left, -2);
  EXPECT_FLOAT_EQ(cam.screen_right, 2);
  EXPECT_FLOAT_EQ(cam.screen_bottom, -1);
  EXPECT_FLOAT_EQ(cam.screen_top, 1);
  EXPECT_FLOAT_EQ(cam.clip_near, 0.5f);
  EXPECT_FLOAT_EQ(cam.clip_far, 20.0f);
  // Unknown projections warn once and fall back to perspective.
  r = parse("Projection \"fisheye\"\nProjection \"fisheye\"\nWorldBegin\nWorldEnd\n");
  EXPECT_EQ(r.scene.camera.projection, mp::Camera::Projection::Perspective);
  EXPECT_EQ(count_warnings(r, "fisheye"), 1);
}

TEST(RibCamera, ImageOptions) {
  const mp::RibResult r = parse(
      "Format 800 600 2\nPixelSamples 2.2 0.3\nPixelFilter \"box\" 1 1\nShadingRate 4\n"
      "Display \"out.png\" \"file\" \"rgba\"\nDisplay \"+second.png\" \"file\" \"rgba\"\n"
      "WorldBegin\nWorldEnd\n");
  const mp::RenderSettings& s = r.scene.settings;
  EXPECT_EQ(s.width, 800);
  EXPECT_EQ(s.height, 600);
  EXPECT_FLOAT_EQ(s.pixel_aspect, 2.0f);
  EXPECT_EQ(s.samples_x, 3);  // rounded up
  EXPECT_EQ(s.samples_y, 1);  // at least 1
  EXPECT_EQ(s.filter, mp::PixelFilter::Box);
  EXPECT_FLOAT_EQ(s.filter_width, 1.0f);
  EXPECT_FLOAT_EQ(s.shading_rate, 4.0f);
  EXPECT_EQ(r.display_name, "out.png");
}

// --- orientation -------------------------------------------------------------------------

// In RenderMan's default (left-handed) orientation a polygon whose vertices
// appear clockwise from the camera faces the camera (RI spec 3.2, 5.1).
// On screen (x right, y up) the order origin -> up -> right is clockwise.
const char* kClockwiseOnScreen = "Polygon \"P\" [0 0 0  0 1 0  1 0 0]\n";
const char* kCounterClockwiseOnScreen = "Polygon \"P\" [0 0 0  1 0 0  0 1 0]\n";

TEST(RibOrientation, ClockwiseFacesTheCameraByDefault) {
  mp::RibResult r = parse("Translate 0 0 5\nWorldBegin\n" + std::string(kClockwiseOnScreen) + "WorldEnd\n");
  EXPECT_TRUE(faces_camera(r.scene, r.scene.meshes[0], 0));
  r = parse("Translate 0 0 5\nWorldBegin\n" + std::string(kCounterClockwiseOnScreen) + "WorldEnd\n");
  EXPECT_FALSE(faces_camera(r.scene, r.scene.meshes[0], 0));
}

TEST(RibOrientation, ReverseOrientationAndInside) {
  for (const char* req : {"ReverseOrientation\n", "Orientation \"inside\"\n", "Orientation \"rh\"\n"}) {
    const mp::RibResult r =
        parse("Translate 0 0 5\nWorldBegin\n" + std::string(req) + kCounterClockwiseOnScreen + "WorldEnd\n");
    EXPECT_TRUE(faces_camera(r.scene, r.scene.meshes[0], 0)) << req;
  }
  for (const char* req : {"Orientation \"outside\"\n", "Orientation \"lh\"\n",
                          "ReverseOrientation\nReverseOrientation\n"}) {
    const mp::RibResult r =
        parse("Translate 0 0 5\nWorldBegin\n" + std::string(req) + kClockwiseOnScreen + "WorldEnd\n");
    EXPECT_TRUE(faces_camera(r.scene, r.scene.meshes[0], 0)) << req;
  }
}

TEST(RibOrientation, MirroringFlipsTheHandedness) {
  // After a mirror the current orientation is right-handed: polygons that
  // appear counter-clockwise from the camera face it.
  for (const char* mirror : {"Scale 1 1 -1\n", "Scale -1 1 1\n"}) {
    const std::string world = "Translate 0 0 5\nWorldBegin\n" + std::string(mirror);
    // The object points of a polygon that is counter-clockwise on screen.
    const std::string ccw = mirror[6] == '1' ? "Polygon \"P\" [0 0 0  1 0 0  0 1 0]\n"
                                             : "Polygon \"P\" [0 0 0  -1 0 0  0 1 0]\n";
    const mp::RibResult r = parse(world + ccw + "WorldEnd\n");
    EXPECT_TRUE(faces_camera(r.scene, r.scene.meshes[0], 0)) << mirror;
    // "lh" asks for left-handed orientation explicitly: now clockwise is front.
    const mp::RibResult l = parse(world + "Orientation \"lh\"\n" + ccw + "WorldEnd\n");
    EXPECT_FALSE(faces_camera(l.scene, l.scene.meshes[0], 0)) << mirror;
  }
  // A mirrored camera transform mirrors the world: same rule.
  const mp::RibResult r = parse("Translate 0 0 5\nScale 1 1 -1\nWorldBegin\n"
                                "Polygon \"P\" [0 0 0  1 0 0  0 1 0]\nWorldEnd\n");
  EXPECT_TRUE(faces_camera(r.scene, r.scene.meshes[0], 0));
}

TEST(RibOrientation, PatchesFollowDpduCrossDpdv) {
  // RenderMan's patch normal is dPdu x dPdv (flipped when inside out).
  // Here dPdu = +y and dPdv = +x, so the normal is -z: towards the camera.
  // Its corner values say which corner each is: (u, v) = (y, x).
  const std::string patch = "Patch \"bilinear\" \"P\" [0 0 0  0 1 0  1 0 0  1 1 0] "
                            "\"varying float[2] micropoly:uv0\" [0 0  1 0  0 1  1 1]\n";
  for (bool reversed : {false, true}) {
    const mp::RibResult r = parse("Translate 0 0 5\nWorldBegin\n" +
                                  std::string(reversed ? "ReverseOrientation\n" : "") + patch +
                                  "WorldEnd\n");
    ASSERT_EQ(r.scene.bezier_patches.size(), 1u);
    const mp::BezierPatches& set = r.scene.bezier_patches[0];
    const auto& cp = set.control_points;
    const glm::vec3 dpdu = cp[3] - cp[0], dpdv = cp[12] - cp[0];
    const glm::mat4 to_camera = r.scene.camera.world_to_camera * set.object_to_world;
    const glm::vec3 n = glm::inverseTranspose(glm::mat3(to_camera)) * glm::cross(dpdu, dpdv);
    const glm::vec3 p = apply(to_camera, cp[5]);
    EXPECT_EQ(glm::dot(n, -p) > 0.0f, !reversed);
    // The corners (0,0), (1,0), (1,1), (0,1) keep their values, mirrored or not.
    ASSERT_EQ(set.uv_layers.size(), 1u);
    const int corner_points[4] = {0, 3, 15, 12};
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(set.uv_layers[0][size_t(c)], glm::vec2(cp[size_t(corner_points[c])].y, cp[size_t(corner_points[c])].x))
          << "corner " << c << (reversed ? " reversed" : "");
  }
}

// --- shading ---------------------------------------------------------------------------------

TEST(RibShading, SurfacesColorsAndMaterialDedupe) {
  const mp::RibResult r = parse_world(
      "Color [0.5 0.25 1]\nOpacity [1 1 0.5]\n"
      "Surface \"plastic\" \"Ka\" 0.1 \"Kd\" 0.2 \"Ks\" 0.3 \"roughness\" 0.4 \"specularcolor\" [0.5 0.6 0.7]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Translate 0 0 1\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n"  // same state: same material
      "Surface \"matte\" \"Kd\" 0.9\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Surface \"constant\"\nColor [1 1 1]\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Surface \"wood\" \"Kd\" [1]\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Surface \"wood\"\nTranslate 0 0 1\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  const mp::Scene& s = r.scene;
  ASSERT_EQ(s.meshes.size(), 6u);
  const mp::Material& plastic = s.materials[static_cast<size_t>(s.meshes[0].material)];
  EXPECT_EQ(plastic.model, mp::Material::Model::Plastic);
  EXPECT_EQ(plastic.color, glm::vec3(0.5f, 0.25f, 1.0f));
  EXPECT_EQ(plastic.opacity, glm::vec3(1.0f, 1.0f, 0.5f));
  EXPECT_FLOAT_EQ(plastic.ka, 0.1f);
  EXPECT_FLOAT_EQ(plastic.kd, 0.2f);
  EXPECT_FLOAT_EQ(plastic.ks, 0.3f);
  EXPECT_FLOAT_EQ(plastic.roughness, 0.4f);
  EXPECT_EQ(plastic.specular_color, glm::vec3(0.5f, 0.6f, 0.7f));
  EXPECT_EQ(s.meshes[1].material, s.meshes[0].material);
  const mp::Material& matte = s.materials[static_cast<size_t>(s.meshes[2].material)];
  EXPECT_EQ(matte.model, mp::Material::Model::Matte);
  EXPECT_FLOAT_EQ(matte.kd, 0.9f);
  EXPECT_FLOAT_EQ(matte.ka, 1.0f);
  const mp::Material& constant = s.materials[static_cast<size_t>(s.meshes[3].material)];
  EXPECT_EQ(constant.model, mp::Material::Model::Constant);
  // Unknown shaders: plastic with its defaults, one warning per shader name.
  const mp::Material& wood = s.materials[static_cast<size_t>(s.meshes[4].material)];
  EXPECT_EQ(wood.model, mp::Material::Model::Plastic);
  EXPECT_FLOAT_EQ(wood.kd, 0.5f);
  EXPECT_FLOAT_EQ(wood.ks, 0.5f);
  EXPECT_FLOAT_EQ(wood.roughness, 0.1f);
  EXPECT_EQ(s.meshes[5].material, s.meshes[4].material);
  EXPECT_EQ(count_warnings(r, "wood"), 1);
  // Distinct states give distinct materials; index 0 stays the default.
  EXPECT_EQ(s.materials.size(), 5u);
  EXPECT_EQ(s.materials[0].model, mp::Material::Model::Matte);
}

TEST(RibShading, SidesMapsToDoubleSided) {
  const mp::RibResult r = parse_world(
      "Sides 1\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\nSides 2\nTranslate 1 0 0\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  ASSERT_EQ(r.scene.meshes.size(), 2u);
  EXPECT_FALSE(r.scene.meshes[0].double_sided);
  EXPECT_TRUE(r.scene.meshes[1].double_sided);
}

TEST(RibLights, ShaderParametersAndDefaults) {
  const mp::RibResult r = parse_world(
      "LightSource \"ambientlight\" 1 \"intensity\" 0.5 \"lightcolor\" [1 0 0]\n"
      "LightSource \"distantlight\" 2\n"
      "LightSource \"pointlight\" 3 \"from\" [1 2 3] \"intensity\" 7\n"
      "LightSource \"spotlight\" 4 \"from\" [0 0 0] \"to\" [0 -2 0]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  const auto& L = r.scene.lights;
  ASSERT_EQ(L.size(), 4u);
  EXPECT_EQ(L[0].type, mp::Light::Type::Ambient);
  EXPECT_FLOAT_EQ(L[0].intensity, 0.5f);
  EXPECT_EQ(L[0].color, glm::vec3(1, 0, 0));
  EXPECT_EQ(L[1].type, mp::Light::Type::Distant);
  expect_near(L[1].direction, {0, 0, 1});  // distantlight: from (0,0,0) to (0,0,1)
  EXPECT_FLOAT_EQ(L[1].intensity, 1.0f);
  EXPECT_EQ(L[2].type, mp::Light::Type::Point);
  expect_near(L[2].position, {1, 2, 3});
  EXPECT_FLOAT_EQ(L[2].intensity, 7.0f);
  EXPECT_EQ(L[3].type, mp::Light::Type::Spot);
  expect_near(L[3].direction, {0, -1, 0});
  EXPECT_NEAR(L[3].cone_angle, glm::radians(30.0f), 1e-6f);
  EXPECT_NEAR(L[3].cone_delta_angle, glm::radians(5.0f), 1e-6f);
  EXPECT_FLOAT_EQ(L[3].beam_distribution, 2.0f);
}

TEST(RibLights, TransformedAtDeclaration) {
  const mp::RibResult r = parse(
      // Before WorldBegin lights are in camera space: this one is at the eye.
      "LightSource \"pointlight\" 1 \"from\" [0 0 0]\n"
      "LightSource \"distantlight\" 2 \"from\" [0 0 0] \"to\" [0 0 1]\n"
      "Translate 0 0 10\nRotate 90 0 1 0\n"
      "WorldBegin\n"
      "Translate 1 2 3\nRotate 90 0 0 1\n"
      "LightSource \"spotlight\" 3 \"from\" [1 0 0] \"to\" [2 0 0]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n");
  const auto& L = r.scene.lights;
  ASSERT_EQ(L.size(), 3u);
  const glm::mat4 cam_to_world = glm::inverse(r.scene.camera.world_to_camera);
  expect_near(L[0].position, apply(cam_to_world, {0, 0, 0}), 1e-4f);
  expect_near(L[0].position, {10, 0, 0}, 1e-4f);  // Rotate 90 about y maps world +x to camera -z
  // The camera-space view axis (+z in RenderMan) in world space.
  expect_near(L[1].direction, {-1, 0, 0}, 1e-5f);
  expect_near(L[2].position, {1, 3, 3}, 1e-5f);
  expect_near(L[2].direction, {0, 1, 0}, 1e-5f);
}

TEST(RibLights, HandlesAndIlluminate) {
  const mp::RibResult r = parse_world(
      "AttributeBegin\n"
      "LightSource \"pointlight\" 1 \"intensity\" 1\n"  // off after AttributeEnd
      "LightSource \"pointlight\" \"named\" \"intensity\" 2\n"
      "AttributeEnd\n"
      "Illuminate \"named\" 1\n"
      "LightSource \"pointlight\" 3 \"intensity\" 3\n"
      "Illuminate 3 0\n"
      "LightSource \"bogus\" 4\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  ASSERT_EQ(r.scene.lights.size(), 1u);
  EXPECT_FLOAT_EQ(r.scene.lights[0].intensity, 2.0f);
  EXPECT_EQ(count_warnings(r, "bogus"), 1);
}

TEST(RibLights, ShadowsOnlyWithAShadowName) {
  // RenderMan's lights cast shadows through a named shadow map: without a
  // name (or with an empty one) a light casts none, whatever its type.
  const mp::RibResult r = parse_world(
      "LightSource \"pointlight\" 1\n"
      "LightSource \"pointlight\" 2 \"string shadowname\" [\"\"]\n"
      "LightSource \"pointlight\" 3 \"string shadowname\" [\"raytrace\"]\n"
      "LightSource \"spotlight\" 4 \"shadowname\" \"spot.shad\"\n"  // any name, declared or not
      "LightSource \"distantlight\" 5 \"shadowname\" [\"raytrace\"]\n"
      "LightSource \"micropoly_arealight\" 6 \"string shadowname\" \"raytrace\"\n"
      "LightSource \"spotlight\" 7\nLightSource \"distantlight\" 8\nLightSource \"micropoly_arealight\" 9\n"
      "LightSource \"ambientlight\" 10 \"string shadowname\" \"raytrace\"\n"
      "LightSource \"ambientlight\" 11 \"string shadowname\" \"raytrace\"\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  const auto& L = r.scene.lights;
  ASSERT_EQ(L.size(), 11u);
  const bool casts[] = {false, false, true, true, true, true, false, false, false, false, false};
  for (size_t i = 0; i < L.size(); ++i) EXPECT_EQ(L[i].cast_shadows, casts[i]) << "light " << i + 1;
  // Ambient light has no shadows: its shadowname is ignored with one warning.
  EXPECT_EQ(count_warnings(r, "\"shadowname\" is ignored"), 1);
  EXPECT_EQ(r.warnings.size(), 1u);
}

TEST(RibLights, SizeForSoftShadows) {
  const mp::RibResult r = parse_world(
      "LightSource \"pointlight\" 1 \"float micropoly:radius\" [0.25] \"integer micropoly:softfalloff\" [0]\n"
      "LightSource \"spotlight\" 2 \"float micropoly:radius\" 1.5 \"integer micropoly:softfalloff\" 1\n"
      "LightSource \"distantlight\" 3 \"float micropoly:angle\" [0.0093]\n"
      "LightSource \"pointlight\" 4\nLightSource \"spotlight\" 5\nLightSource \"distantlight\" 6\n"
      // Parameters of another light type are ignored with a warning.
      "LightSource \"pointlight\" 7 \"float micropoly:angle\" [0.5]\n"
      "LightSource \"distantlight\" 8 \"float micropoly:radius\" [2]\n"
      "LightSource \"micropoly_arealight\" 9 \"float micropoly:radius\" [2]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  const auto& L = r.scene.lights;
  ASSERT_EQ(L.size(), 9u);
  EXPECT_EQ(L[0].radius, 0.25f);
  EXPECT_FALSE(L[0].soft_falloff);
  EXPECT_EQ(L[1].radius, 1.5f);
  EXPECT_TRUE(L[1].soft_falloff);
  EXPECT_EQ(L[2].angle, 0.0093f);
  // Defaults: a point, with soft falloff; a sun of no size.
  for (size_t i : {3u, 4u}) {
    EXPECT_EQ(L[i].radius, 0.0f) << i;
    EXPECT_TRUE(L[i].soft_falloff) << i;
  }
  EXPECT_EQ(L[5].angle, 0.0f);
  EXPECT_EQ(L[6].angle, 0.0f);
  EXPECT_EQ(L[7].radius, 0.0f);
  EXPECT_EQ(L[8].radius, 0.0f);
  EXPECT_EQ(count_warnings(r, "\"micropoly:angle\" is ignored"), 1);
  EXPECT_EQ(count_warnings(r, "\"micropoly:radius\" is ignored"), 2);  // once per light shader
  EXPECT_EQ(r.warnings.size(), 3u);
}

// --- ray visibility -------------------------------------------------------------------------------

TEST(RibVisibility, CameraAndTransmissionAreScopedAttributes) {
  const mp::RibResult r = parse_world(
      "Attribute \"identifier\" \"name\" \"default\"\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "AttributeBegin\n"
      "  Attribute \"identifier\" \"name\" \"hidden\"\n"
      "  Attribute \"visibility\" \"int camera\" [0]\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "  AttributeBegin\n"
      "    Attribute \"identifier\" \"name\" \"neither\"\n"
      "    Attribute \"visibility\" \"integer transmission\" [0] \"int diffuse\" [1]\n"
      "    Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "  AttributeEnd\n"
      "  Attribute \"identifier\" \"name\" \"hidden again\"\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "  Attribute \"identifier\" \"name\" \"no shadow\"\n"
      "  Attribute \"visibility\" \"int camera\" 1 \"int transmission\" 0 \"int diffuse\" 0 \"int specular\" 0\n"
      "  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "AttributeEnd\n"
      "Attribute \"identifier\" \"name\" \"restored\"\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  struct Expect {
    const char* name;
    bool camera, shadows;
  };
  const Expect expected[] = {{"default", true, true},     {"hidden", false, true},   {"neither", false, false},
                             {"hidden again", false, true}, {"no shadow", true, false}, {"restored", true, true}};
  for (const Expect& e : expected) {
    const mp::Mesh* m = find_mesh(r.scene, e.name);
    ASSERT_NE(m, nullptr) << e.name;
    EXPECT_EQ(m->visible_camera, e.camera) << e.name;
    EXPECT_EQ(m->cast_shadows, e.shadows) << e.name;
  }
  // Other kinds of rays are ignored, with one warning per parameter name.
  EXPECT_EQ(count_warnings(r, "\"diffuse\" is ignored"), 1);
  EXPECT_EQ(count_warnings(r, "\"specular\" is ignored"), 1);
  EXPECT_EQ(r.warnings.size(), 2u);
}

TEST(RibVisibility, PolygonAndPatchRunsMergeOnlyWithEqualVisibility) {
  const std::string patch = "Patch \"bilinear\" \"P\" [0 0 0 1 0 0 0 1 0 1 1 0]\n";
  const mp::RibResult r = parse_world(
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\nPolygon \"P\" [0 0 1 1 0 1 0 1 1]\n"  // one mesh
      "Attribute \"visibility\" \"int transmission\" [0]\n"
      "Polygon \"P\" [0 0 2 1 0 2 0 1 2]\nPolygon \"P\" [0 0 3 1 0 3 0 1 3]\n"  // a second one
      "Attribute \"visibility\" \"int camera\" [0] \"int transmission\" [1]\n"
      "Polygon \"P\" [0 0 4 1 0 4 0 1 4]\n"  // a third
      "Attribute \"visibility\" \"int camera\" [0]\n"  // the same state again: still the third
      "Polygon \"P\" [0 0 5 1 0 5 0 1 5]\n" +
      patch + patch + "Attribute \"visibility\" \"int camera\" [1]\n" + patch);
  const mp::Scene& s = r.scene;
  ASSERT_EQ(s.meshes.size(), 3u);
  EXPECT_EQ(s.meshes[0].face_vertex_counts.size(), 2u);
  EXPECT_TRUE(s.meshes[0].visible_camera && s.meshes[0].cast_shadows);
  EXPECT_EQ(s.meshes[1].face_vertex_counts.size(), 2u);
  EXPECT_TRUE(s.meshes[1].visible_camera);
  EXPECT_FALSE(s.meshes[1].cast_shadows);
  EXPECT_EQ(s.meshes[2].face_vertex_counts.size(), 2u);
  EXPECT_FALSE(s.meshes[2].visible_camera);
  EXPECT_TRUE(s.meshes[2].cast_shadows);
  ASSERT_EQ(s.bezier_patches.size(), 2u);
  EXPECT_EQ(s.bezier_patches[0].control_points.size(), 32u);
  EXPECT_FALSE(s.bezier_patches[0].visible_camera);
  EXPECT_TRUE(s.bezier_patches[0].cast_shadows);
  EXPECT_EQ(s.bezier_patches[1].control_points.size(), 16u);
  EXPECT_TRUE(s.bezier_patches[1].visible_camera);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RibVisibility, InstancesTakeTheVisibilityWhereTheyAreInstanced) {
  // As Sides and the material: the state at ObjectInstance applies, and a
  // visibility set inside the definition does not.
  const mp::RibResult r = parse_world(
      "ObjectBegin \"thing\"\n"
      "  Attribute \"visibility\" \"int camera\" [0] \"int transmission\" [0]\n"
      "  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "ObjectEnd\n"
      "ObjectInstance \"thing\"\n"
      "AttributeBegin\nAttribute \"visibility\" \"int transmission\" [0]\nObjectInstance \"thing\"\nAttributeEnd\n"
      "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\nObjectInstance \"thing\"\nAttributeEnd\n");
  ASSERT_EQ(r.scene.instances.size(), 3u);
  const mp::Scene s = mp::with_instances_made_real(r.scene);
  ASSERT_EQ(s.meshes.size(), 3u);
  EXPECT_TRUE(s.meshes[0].visible_camera);
  EXPECT_TRUE(s.meshes[0].cast_shadows);
  EXPECT_TRUE(s.meshes[1].visible_camera);
  EXPECT_FALSE(s.meshes[1].cast_shadows);
  EXPECT_FALSE(s.meshes[2].visible_camera);
  EXPECT_TRUE(s.meshes[2].cast_shadows);
}

// --- the complete request set ----------------------------------------------------------------

TEST(RibAllRequests, EveryRequestLandsInTheScene) {
  const mp::RibResult r = mp::read_rib_file(kScenes + "/all_requests.rib");
  const mp::Scene& s = r.scene;
  // Options and camera.
  EXPECT_EQ(r.display_name, "all_requests.exr");
  EXPECT_EQ(s.settings.width, 320);
  EXPECT_EQ(s.settings.height, 200);
  EXPECT_FLOAT_EQ(s.settings.pixel_aspect, 1.5f);
  EXPECT_EQ(s.settings.samples_x, 4);
  EXPECT_EQ(s.settings.samples_y, 2);
  EXPECT_EQ(s.settings.filter, mp::PixelFilter::Triangle);
  EXPECT_FLOAT_EQ(s.settings.filter_width, 3.0f);
  EXPECT_FLOAT_EQ(s.settings.shading_rate, 0.5f);
  EXPECT_FLOAT_EQ(s.settings.crop_x0, 0.1f);
  EXPECT_FLOAT_EQ(s.settings.crop_x1, 0.9f);
  EXPECT_FLOAT_EQ(s.settings.crop_y0, 0.2f);
  EXPECT_FLOAT_EQ(s.settings.crop_y1, 0.8f);
  EXPECT_FLOAT_EQ(s.camera.clip_near, 0.5f);
  EXPECT_FLOAT_EQ(s.camera.clip_far, 500.0f);
  EXPECT_FLOAT_EQ(s.camera.fov_degrees, 50.0f);
  EXPECT_FLOAT_EQ(s.camera.screen_left, -1.5f);
  EXPECT_FLOAT_EQ(s.camera.screen_top, 1.0f);
  // Camera: Translate 0 0 10, Rotate 90 about z: world +x is camera +y.
  expect_near(apply(s.camera.world_to_camera, {1, 0, 0}), {0, 1, -10}, 1e-5f);

  // Lights: the camera-space pointlight is at the eye.
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_EQ(s.lights[0].type, mp::Light::Type::Point);
  expect_near(s.lights[0].position, {0, 0, -10}, 1e-5f);
  EXPECT_FLOAT_EQ(s.lights[0].intensity, 2.0f);
  EXPECT_EQ(s.lights[1].type, mp::Light::Type::Ambient);
  EXPECT_EQ(s.lights[1].color, glm::vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(s.lights[2].type, mp::Light::Type::Distant);
  expect_near(s.lights[2].direction, {0, -1, 0});
  EXPECT_EQ(s.lights[3].type, mp::Light::Type::Spot);
  expect_near(s.lights[3].position, {1, 2, 3});
  expect_near(s.lights[3].direction, {0, 0, -1});
  EXPECT_FLOAT_EQ(s.lights[3].cone_angle, 0.5f);
  EXPECT_FLOAT_EQ(s.lights[3].cone_delta_angle, 0.1f);
  EXPECT_FLOAT_EQ(s.lights[3].beam_distribution, 3.0f);
  EXPECT_FLOAT_EQ(s.lights[3].intensity, 20.0f);

  // Consecutive Polygons merged into one mesh.
  const mp::Mesh* tri = find_mesh(s, "triangles");
  ASSERT_NE(tri, nullptr);
  EXPECT_EQ(tri->face_vertex_counts, (std::vector<int>{3, 3}));
  EXPECT_EQ(tri->face_vertex_indices, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(tri->material, 0);

  const mp::Mesh* quad = find_mesh(s, "red_quad");
  ASSERT_NE(quad, nullptr);
  EXPECT_FALSE(quad->double_sided);
  expect_near(apply(quad->object_to_world, {1, 0, 0}), {3, 0, 0});
  const mp::Material& red = s.materials[static_cast<size_t>(quad->material)];
  EXPECT_EQ(red.model, mp::Material::Model::Plastic);
  EXPECT_EQ(red.color, glm::vec3(1, 0, 0));
  EXPECT_EQ(red.opacity, glm::vec3(0.5f));
  EXPECT_FLOAT_EQ(red.ka, 0.5f);
  EXPECT_FLOAT_EQ(red.kd, 0.7f);
  EXPECT_FLOAT_EQ(red.ks, 0.3f);
  EXPECT_FLOAT_EQ(red.roughness, 0.2f);
  EXPECT_EQ(red.specular_color, glm::vec3(1, 1, 0));

  // GeneralPolygon (outer loop only) under ConcatTransform, then
  // PointsGeneralPolygons after TransformEnd.
  const mp::Mesh* gp = find_mesh(s, "matte_polygons", 0);
  const mp::Mesh* pgp = find_mesh(s, "matte_polygons", 1);
  ASSERT_NE(gp, nullptr);
  ASSERT_NE(pgp, nullptr);
  EXPECT_EQ(gp->face_vertex_counts, (std::vector<int>{4}));
  EXPECT_EQ(gp->points.size(), 4u);
  expect_near(apply(gp->object_to_world, {0, 0, 0}), {5, 6, 7});
  EXPECT_EQ(pgp->face_vertex_counts, (std::vector<int>{3, 4}));
  EXPECT_EQ(pgp->face_vertex_indices, (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  expect_near(apply(pgp->object_to_world, {0, 0, 0}), {0, 0, 0});
  EXPECT_EQ(s.materials[static_cast<size_t>(gp->material)].model, mp::Material::Model::Matte);
  EXPECT_FLOAT_EQ(s.materials[static_cast<size_t>(gp->material)].kd, 0.8f);

  const mp::Mesh* sd = find_mesh(s, "constant_subdiv");
  ASSERT_NE(sd, nullptr);
  EXPECT_EQ(sd->scheme, mp::SubdivScheme::CatmullClark);
  EXPECT_EQ(sd->crease_vertices, (std::vector<int>{0, 4, 4, 8}));
  EXPECT_EQ(sd->crease_sharpness, (std::vector<float>{2.5f, 2.5f}));
  EXPECT_EQ(sd->corner_vertices, (std::vector<int>{2}));
  EXPECT_EQ(sd->corner_sharpness, (std::vector<float>{4.0f}));
  EXPECT_EQ(sd->hole_faces, (std::vector<int>{3}));
  EXPECT_EQ(sd->boundary, mp::BoundaryInterpolation::EdgeOnly);
  expect_near(apply(sd->object_to_world, {1, 1, 1}), {2, 2, 2});
  EXPECT_EQ(s.materials[static_cast<size_t>(sd->material)].model, mp::Material::Model::Constant);
  EXPECT_EQ(s.materials[static_cast<size_t>(sd->material)].color, glm::vec3(0.2f, 0.4f, 0.6f));

  // Patches: 2 from the PatchMesh, one power/Bezier patch, one bilinear; the
  // runs share one set.
  ASSERT_EQ(s.bezier_patches.size(), 1u);
  EXPECT_EQ(s.bezier_patches[0].name, "patches");
  EXPECT_EQ(s.bezier_patches[0].control_points.size(), 4u * 16u);

  const mp::Scene real = mp::with_instances_made_real(s);
  const mp::Mesh* inst = find_mesh(real, "instance");
  ASSERT_NE(inst, nullptr);
  expect_near(apply(inst->object_to_world, {0, 0, 0}), {10, 0, 1});

  const mp::Mesh* archived = find_mesh(s, "from_archive");
  ASSERT_NE(archived, nullptr);
  EXPECT_EQ(s.materials[static_cast<size_t>(archived->material)].color, glm::vec3(0, 1, 0));

  // Orientation: inside (reversed), reversed back, rh (reversed), lh.
  const std::vector<int> as_given{0, 1, 2}, reversed{2, 1, 0};
  for (int k = 0; k < 4; ++k) {
    const mp::Mesh* m = find_mesh(s, "orientation", k);
    ASSERT_NE(m, nullptr) << k;
    EXPECT_EQ(m->face_vertex_indices, (k == 0 || k == 2) ? reversed : as_given) << k;
  }

  const mp::Mesh* cs = find_mesh(s, "coordsys");
  ASSERT_NE(cs, nullptr);
  expect_near(apply(cs->object_to_world, {1, 0, 0}), {1, 5, 0});

  // Exactly these warnings: the ignored option, the parameter matte does not
  // have, and the dropped holes of the general polygons.
  EXPECT_EQ(r.warnings.size(), 3u);
  EXPECT_EQ(count_warnings(r, "Option \"searchpath\""), 1);
  EXPECT_EQ(count_warnings(r, "\"myfloat\""), 1);
  EXPECT_EQ(count_warnings(r, "holes"), 1);
}

// --- structure, archives, instancing ---------------------------------------------------------

TEST(RibStructure, UnsupportedRequestsWarnOncePerName) {
  const mp::RibResult r = parse_world(
      "Atmosphere \"fog\"\nAtmosphere \"fog\" \"distance\" [2]\nExposure 1 2.2\nAtmosphere [\"fog\"]\n"
      "Hider \"hidden\"\nHider \"hidden\"\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  EXPECT_EQ(count_warnings(r, "'Atmosphere'"), 1);
  EXPECT_EQ(count_warnings(r, "'Exposure'"), 1);
  EXPECT_EQ(count_warnings(r, "'Hider'"), 1);
  EXPECT_EQ(r.warnings.size(), 3u);
  EXPECT_EQ(r.scene.meshes.size(), 1u);  // arguments were skipped cleanly
  EXPECT_NE(r.warnings[0].find("test.rib:2:"), std::string::npos) << r.warnings[0];
}

TEST(RibStructure, OnlyTheFirstFrameIsRendered) {
  const mp::RibResult r = parse(
      "FrameBegin 1\nWorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\nFrameEnd\n"
      "FrameBegin 2\nWorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\nFrameEnd\n"
      "FrameBegin 3\nWorldBegin\nWorldEnd\nFrameEnd\n");
  EXPECT_EQ(r.scene.meshes.size(), 1u);
  EXPECT_EQ(count_warnings(r, "first frame"), 1);
}

TEST(RibMotion, TransformsMoveObjectsOverTheShutter) {
  // Two times over the shutter: two steps; the centre is their mean. A
  // transformation after the block moves both steps alike.
  const mp::RibResult r = parse_world(
      "MotionBegin [0 1]\nTranslate 1 0 0\nTranslate 5 0 0\nMotionEnd\nTranslate 0 2 0\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  const mp::Mesh& m = r.scene.meshes[0];
  EXPECT_EQ(r.scene.motion_steps, 2);
  ASSERT_EQ(m.motion_object_to_world.size(), 2u);
  expect_near(apply(m.motion_object_to_world[0], {0, 0, 0}), {1, 2, 0});
  expect_near(apply(m.motion_object_to_world[1], {0, 0, 0}), {5, 2, 0});
  expect_near(apply(m.object_to_world, {0, 0, 0}), {3, 2, 0});
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RibMotion, BlocksThatMoveNothingLeaveAStillScene) {
  // No shape follows the moving transform, or it moves only an object
  // definition that is never placed: nothing moves, so no motion steps.
  EXPECT_EQ(parse_world("MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 5 0 0\nMotionEnd\n").scene.motion_steps, 0);
  EXPECT_EQ(parse_world("ObjectBegin 1\nMotionBegin [0 1]\nTranslate 0 0 0\nTranslate 5 0 0\nMotionEnd\n"
                        "ObjectEnd\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n")
                .scene.motion_steps,
            0);
}

TEST(RibPrograms, ProgramsNoMaterialUsesAreDropped) {
  // Material 1 redefined without its program: the program is unused.
  const mp::RibResult r = parse_world(
      "Attribute \"micropoly\" \"integer material\" [1] \"string program\" [\"first\"]\n"
      "Attribute \"micropoly\" \"integer material\" [1]\n"
      "Attribute \"micropoly\" \"integer material\" [2] \"string program\" [\"second\"]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  ASSERT_EQ(r.scene.material_programs.size(), 1u);
  EXPECT_EQ(r.scene.material_programs[0].source, "second");
  // Numbered by first use in material order, not by where the file names
  // them, so a written scene reads back with the same numbers.
  const mp::RibResult two = parse_world(
      "Attribute \"micropoly\" \"integer material\" [1] \"string program\" [\"one\"]\n"
      "Attribute \"micropoly\" \"integer material\" [0] \"string program\" [\"zero\"]\n");
  ASSERT_EQ(two.scene.material_programs.size(), 2u);
  EXPECT_EQ(two.scene.material_programs[0].source, "zero");
  EXPECT_EQ(two.scene.material_programs[1].source, "one");
  int users = 0;
  for (const mp::Material& m : r.scene.materials) users += m.program == 0;
  EXPECT_EQ(users, 1);
}

TEST(RibMotion, ShutterCameraAndDeformation) {
  const mp::RibResult r = parse(
      "Shutter 0 0.5\nMotionBegin [0 0.25 0.5]\nTranslate 0 0 5\nTranslate 0 0 6\nTranslate 0 0 7\nMotionEnd\n"
      "WorldBegin\nMotionBegin [0 0.25 0.5]\n"
      "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 2 0 0 0 1 0]\n"
      "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 3 0 0 0 1 0]\nMotionEnd\nWorldEnd\n");
  EXPECT_EQ(r.scene.motion_steps, 3);
  ASSERT_EQ(r.scene.camera.motion_world_to_camera.size(), 3u);
  expect_near(apply(r.scene.camera.motion_world_to_camera[2], {0, 0, 0}), {0, 0, -7});
  expect_near(apply(r.scene.camera.world_to_camera, {0, 0, 0}), {0, 0, -6});
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  const mp::Mesh& m = r.scene.meshes[0];
  ASSERT_EQ(m.motion_points.size(), 3u);
  EXPECT_FLOAT_EQ(m.motion_points[2][1].x, 3.0f);
  EXPECT_FLOAT_EQ(m.points[1].x, 2.0f);  // the middle step
}

TEST(RibMotion, UnevenTimesUseTheFirstSample) {
  const mp::RibResult r = parse_world(
      "Shutter 0 1\nMotionBegin [0 0.2 1]\nTranslate 1 0 0\nTranslate 2 0 0\nTranslate 5 0 0\nMotionEnd\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  expect_near(apply(r.scene.meshes[0].object_to_world, {0, 0, 0}), {1, 0, 0});
  EXPECT_TRUE(r.scene.meshes[0].motion_object_to_world.empty());
  EXPECT_EQ(count_warnings(r, "evenly spread"), 1);
}

TEST(RibStructure, LexicalDetails) {
  const mp::RibResult r = parse(
      "##RenderMan RIB-Structure 1.1\n"
      "# a comment with UTF-8: caf\xC3\xA9 \xE2\x9C\x93\n"
      "Display \"a\\\"b\\\\c\\101\\n\" \"file\" \"rgba\" # trailing comment\n"
      "Format 1e2 +2E+1 -1\n"
      "WorldBegin Translate .5 -0.25e-1 3.\n"
      "Polygon \"P\"[0 0 0 1 0 0 0 1 0]WorldEnd\n");
  EXPECT_EQ(r.display_name, "a\"b\\cA\n");
  EXPECT_EQ(r.scene.settings.width, 100);
  EXPECT_EQ(r.scene.settings.height, 20);
  EXPECT_FLOAT_EQ(r.scene.settings.pixel_aspect, 1.0f);  // non-positive means default
  expect_near(apply(r.scene.meshes[0].object_to_world, {0, 0, 0}), {0.5f, -0.025f, 3.0f});
}

TEST(RibStructure, DeclareAndInlineDeclarations) {
  const mp::RibResult r = parse_world(
      "Declare \"Kd\" \"uniform float\"\n"
      "Surface \"matte\" \"uniform float Ka\" [0.25] \"Kd\" 0.75\n"
      "Polygon \"vertex point P\" [0 0 0 1 0 0 0 1 0] \"varying float[2] st\" [0 0 1 0 0 1]\n");
  const mp::Material& m = r.scene.materials[static_cast<size_t>(r.scene.meshes[0].material)];
  EXPECT_FLOAT_EQ(m.ka, 0.25f);
  EXPECT_FLOAT_EQ(m.kd, 0.75f);
  EXPECT_EQ(count_warnings(r, "\"st\""), 1);  // an ignored primitive variable
}

TEST(RibStructure, HomogeneousPointsAreDividedByW) {
  const mp::RibResult r = parse_world("Polygon \"Pw\" [0 0 0 2  2 0 0 2  0 4 0 2]\n");
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  expect_near(r.scene.meshes[0].points[1], {1, 0, 0});
  expect_near(r.scene.meshes[0].points[2], {0, 2, 0});
}

TEST(RibStructure, PolygonVariants) {
  const mp::RibResult r = parse_world(
      "Attribute \"identifier\" \"name\" \"pp\"\n"
      "PointsPolygons [3 4] [0 1 2  2 1 3 4] \"P\" [0 0 0 1 0 0 0 1 0 1 1 0 2 2 0]\n"
      "Attribute \"identifier\" \"name\" \"pgp\"\n"
      "PointsGeneralPolygons [2 1] [4 3 3] [0 1 2 3  4 5 6  0 1 2]\n"
      "  \"P\" [0 0 0 4 0 0 4 4 0 0 4 0 1 1 0 2 1 0 1 2 0]\n");
  const mp::Mesh* pp = find_mesh(r.scene, "pp");
  ASSERT_NE(pp, nullptr);
  EXPECT_EQ(pp->face_vertex_counts, (std::vector<int>{3, 4}));
  EXPECT_EQ(pp->points.size(), 5u);
  const mp::Mesh* pgp = find_mesh(r.scene, "pgp");
  ASSERT_NE(pgp, nullptr);
  EXPECT_EQ(pgp->face_vertex_counts, (std::vector<int>{4, 3}));
  EXPECT_EQ(pgp->face_vertex_indices, (std::vector<int>{0, 1, 2, 3, 0, 1, 2}));
  EXPECT_EQ(count_warnings(r, "holes"), 1);
}

std::string write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

TEST(RibArchives, RelativeToTheIncludingFile) {
  const std::string dir = testing::TempDir() + "/rib_archives";
  ASSERT_EQ(std::system(("mkdir -p " + dir + "/sub").c_str()), 0);
  write_file(dir + "/sub/leaf.rib", "Attribute \"identifier\" \"name\" \"leaf\"\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  write_file(dir + "/sub/part.rib", "Translate 1 0 0\nReadArchive \"leaf.rib\"\n");
  write_file(dir + "/main.rib", "WorldBegin\nReadArchive \"sub/part.rib\"\nWorldEnd\n");
  const mp::RibResult r = mp::read_rib_file(dir + "/main.rib");
  const mp::Mesh* leaf = find_mesh(r.scene, "leaf");
  ASSERT_NE(leaf, nullptr);
  // The archive shares the graphics state: its Translate applies.
  expect_near(apply(leaf->object_to_world, {0, 0, 0}), {1, 0, 0});
}

TEST(RibObjects, InstancesUseTheInstanceTransformAndAttributes) {
  const mp::RibResult r = parse_world(
      "ObjectBegin \"thing\"\n"
      "  Scale 2 2 2\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "  Translate 0 0 1\n  Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "ObjectEnd\n"
      "AttributeBegin\nTranslate 10 0 0\nColor [1 0 0]\nSides 1\nObjectInstance \"thing\"\nAttributeEnd\n"
      "AttributeBegin\nRotate 90 0 0 1\nObjectInstance \"thing\"\nAttributeEnd\n");
  ASSERT_EQ(r.scene.prototypes.size(), 1u);  // one definition, placed twice
  ASSERT_EQ(r.scene.instances.size(), 2u);
  const mp::Scene s = mp::with_instances_made_real(r.scene);
  ASSERT_EQ(s.meshes.size(), 4u);
  expect_near(apply(s.meshes[0].object_to_world, {1, 0, 0}), {12, 0, 0});
  expect_near(apply(s.meshes[1].object_to_world, {0, 0, 0}), {10, 0, 2});
  expect_near(apply(s.meshes[2].object_to_world, {1, 0, 0}), {0, 2, 0});
  EXPECT_FALSE(s.meshes[0].double_sided);
  EXPECT_TRUE(s.meshes[2].double_sided);
  EXPECT_EQ(s.materials[static_cast<size_t>(s.meshes[0].material)].color, glm::vec3(1, 0, 0));
  EXPECT_EQ(s.meshes[2].material, 0);
}

// --- subdivision meshes -----------------------------------------------------------------------

TEST(RibSubdiv, TagsFromTheSceneFile) {
  const mp::RibResult r = mp::read_rib_file(kScenes + "/subdiv_creases.rib");
  EXPECT_TRUE(r.warnings.empty());
  const mp::Mesh* cube = find_mesh(r.scene, "creased_cube");
  ASSERT_NE(cube, nullptr);
  EXPECT_EQ(cube->scheme, mp::SubdivScheme::CatmullClark);
  EXPECT_EQ(cube->points.size(), 8u);
  EXPECT_EQ(cube->face_vertex_counts.size(), 6u);
  EXPECT_EQ(cube->crease_vertices, (std::vector<int>{3, 7, 7, 6, 6, 2, 2, 3}));
  EXPECT_EQ(cube->crease_sharpness, (std::vector<float>{3, 3, 3, 3}));
  EXPECT_EQ(cube->corner_vertices, (std::vector<int>{0}));
  EXPECT_EQ(cube->corner_sharpness, (std::vector<float>{10}));
  EXPECT_TRUE(cube->hole_faces.empty());
  EXPECT_EQ(cube->boundary, mp::BoundaryInterpolation::None);  // no tag: RenderMan's default
  const mp::Mesh* grid = find_mesh(r.scene, "grid_with_hole");
  ASSERT_NE(grid, nullptr);
  EXPECT_EQ(grid->hole_faces, (std::vector<int>{4}));
  EXPECT_EQ(grid->boundary, mp::BoundaryInterpolation::EdgeAndCorner);
  // The cube's faces are outward for RenderMan: every face's front is outside.
  const glm::mat4 to_camera = r.scene.camera.world_to_camera * cube->object_to_world;
  const glm::vec3 centre = apply(to_camera, {0, 0, 0});
  for (int f = 0; f < 6; ++f) {
    const glm::vec3 n = front_normal_in_camera(r.scene, *cube, f);
    const glm::vec3 on_face = apply(to_camera, cube->points[static_cast<size_t>(cube->face_vertex_indices[static_cast<size_t>(4 * f)])]);
    EXPECT_GT(glm::dot(n, on_face - centre), 0.0f) << "face " << f;
  }
}

TEST(RibSubdiv, InterpolateBoundaryModes) {
  const std::string mesh =
      "SubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] %TAGS% \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n";
  auto boundary = [&](const std::string& tags) {
    std::string text = mesh;
    text.replace(text.find("%TAGS%"), 6, tags);
    return parse_world(text).scene.meshes.at(0).boundary;
  };
  using B = mp::BoundaryInterpolation;
  EXPECT_EQ(boundary(""), B::None);
  EXPECT_EQ(boundary("[] [] [] []"), B::None);
  EXPECT_EQ(boundary("[\"interpolateboundary\"] [0 0] [] []"), B::EdgeAndCorner);
  EXPECT_EQ(boundary("[\"interpolateboundary\"] [1 0] [0] []"), B::None);
  EXPECT_EQ(boundary("[\"interpolateboundary\"] [1 0] [1] []"), B::EdgeAndCorner);
  EXPECT_EQ(boundary("[\"interpolateboundary\"] [1 0] [2] []"), B::EdgeOnly);
}

TEST(RibSubdiv, PerEdgeSharpnessSchemesAndUnknownTags) {
  const mp::RibResult r = parse_world(
      "SubdivisionMesh \"catmull-clark\" [4] [0 1 2 3] [\"crease\" \"facevaryinginterpolateboundary\"]\n"
      "  [3 2  1 0] [0 1 2  1] [1.5 2.5] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
      "SubdivisionMesh \"bilinear\" [4] [0 1 2 3] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
      "SubdivisionMesh \"loop\" [3] [0 1 2] \"P\" [0 0 0 1 0 0 1 1 0]\n");
  ASSERT_EQ(r.scene.meshes.size(), 2u);
  EXPECT_EQ(r.scene.meshes[0].crease_vertices, (std::vector<int>{0, 1, 1, 2}));
  EXPECT_EQ(r.scene.meshes[0].crease_sharpness, (std::vector<float>{1.5f, 2.5f}));
  EXPECT_EQ(r.scene.meshes[1].scheme, mp::SubdivScheme::None);
  EXPECT_EQ(count_warnings(r, "facevaryinginterpolateboundary"), 1);
  EXPECT_EQ(count_warnings(r, "\"loop\""), 1);
}

}  // namespace
