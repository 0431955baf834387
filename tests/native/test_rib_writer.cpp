// RIB writer: Scene -> RIB -> Scene gives the same Scene (field by field,
// exact where floats are printed to read back exactly), and renders the same
// image. Also the reader's side of the "micropoly" extensions the writer uses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>

#include "io/image_io.h"
#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "renderer_fixture.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene_fixtures.h"

namespace mp::test {
namespace {

// Texture images go to a folder of this process (ctest runs tests side by
// side, each in its own process); the RIB names them by absolute path, so
// the string reads back from anywhere.
std::string texture_folder() { return ::testing::TempDir() + "/rib_writer_textures_" + std::to_string(::getpid()); }

std::string to_rib(const Scene& scene) {
  std::ostringstream out;
  write_rib(scene, out, "", texture_folder());
  return out.str();
}

// Writes and reads back; the file must read without warnings (a warning
// means something was dropped).
Scene round_trip(const Scene& scene) {
  const std::string text = to_rib(scene);
  RibReadOptions options;  // the textures are written to an absolute temporary folder
  options.allowed_roots = {texture_folder()};
  RibResult r = read_rib_string(text, "written.rib", ".", options);
  for (const std::string& w : r.warnings) ADD_FAILURE() << "warning: " << w << "\n" << text;
  return std::move(r.scene);
}

// --- field-by-field comparison ---------------------------------------------------

void expect_same_settings(const RenderSettings& a, const RenderSettings& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.pixel_aspect, b.pixel_aspect);
  EXPECT_EQ(a.crop_x0, b.crop_x0);
  EXPECT_EQ(a.crop_x1, b.crop_x1);
  EXPECT_EQ(a.crop_y0, b.crop_y0);
  EXPECT_EQ(a.crop_y1, b.crop_y1);
  EXPECT_EQ(a.samples_x, b.samples_x);
  EXPECT_EQ(a.samples_y, b.samples_y);
  EXPECT_EQ(a.shading_rate, b.shading_rate);
  EXPECT_EQ(a.filter, b.filter);
  EXPECT_EQ(a.filter_width, b.filter_width);
  EXPECT_EQ(a.bound_split, b.bound_split);
  EXPECT_EQ(a.bound_split_memory_mib, b.bound_split_memory_mib);
  EXPECT_EQ(a.max_grid_size, b.max_grid_size);
  EXPECT_EQ(a.max_split_depth, b.max_split_depth);
  EXPECT_EQ(a.backface_culling, b.backface_culling);
  EXPECT_EQ(a.depth_and_normal_passes, b.depth_and_normal_passes);
  EXPECT_EQ(a.shadows, b.shadows);
  EXPECT_EQ(a.shadow_memory_mib, b.shadow_memory_mib);
  EXPECT_EQ(a.shadow_shading_rate, b.shadow_shading_rate);
  EXPECT_EQ(a.occlusion_culling, b.occlusion_culling);
  EXPECT_EQ(a.sample_culling, b.sample_culling);
  EXPECT_EQ(a.holdout_covers, b.holdout_covers);
  EXPECT_EQ(a.visibility_first, b.visibility_first);
  EXPECT_EQ(a.resolver, b.resolver);
  EXPECT_EQ(a.occlusion_waves, b.occlusion_waves);
  EXPECT_EQ(a.bound_split_chain, b.bound_split_chain);
  EXPECT_EQ(a.bound_split_steps, b.bound_split_steps);
}

void expect_same_camera(const Camera& a, const Camera& b) {
  EXPECT_EQ(a.projection, b.projection);
  EXPECT_EQ(a.world_to_camera, b.world_to_camera);  // exact, all 16 floats
  if (a.projection == Camera::Projection::Perspective) EXPECT_EQ(a.fov_degrees, b.fov_degrees);
  if (a.screen_left != a.screen_right || a.screen_bottom != a.screen_top) {
    EXPECT_EQ(a.screen_left, b.screen_left);
    EXPECT_EQ(a.screen_right, b.screen_right);
    EXPECT_EQ(a.screen_bottom, b.screen_bottom);
    EXPECT_EQ(a.screen_top, b.screen_top);
  } else {
    EXPECT_EQ(b.screen_left, b.screen_right);  // still "derive from the aspect ratio"
  }
  // RenderMan needs near > 0: 0 comes back as the smallest positive float.
  EXPECT_EQ(a.clip_near > 0 ? a.clip_near : std::numeric_limits<float>::denorm_min(), b.clip_near);
  EXPECT_EQ(a.clip_far, b.clip_far);
  EXPECT_EQ(a.lens_radius, b.lens_radius);
  if (a.lens_radius > 0.0f) {
    EXPECT_EQ(a.focus_distance, b.focus_distance);
    EXPECT_EQ(a.aperture_blades, b.aperture_blades);
    EXPECT_EQ(a.aperture_rotation, b.aperture_rotation);
    EXPECT_EQ(a.aperture_ratio, b.aperture_ratio);
  }
}

// The fields each model shades with (scene.h); the others have no effect.
void expect_same_material(const Material& a, const Material& b) {
  SCOPED_TRACE("material '" + a.name + "'");
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.opacity, b.opacity);
  EXPECT_EQ(a.emission, b.emission);
  switch (a.model) {
    case Material::Model::Constant: break;
    case Material::Model::Plastic:
      EXPECT_EQ(a.ks, b.ks);
      EXPECT_EQ(a.roughness, b.roughness);
      EXPECT_EQ(a.specular_color, b.specular_color);
      [[fallthrough]];
    case Material::Model::Matte:
      EXPECT_EQ(a.ka, b.ka);
      EXPECT_EQ(a.kd, b.kd);
      break;
    case Material::Model::Principled:
      EXPECT_EQ(a.metallic, b.metallic);
      EXPECT_EQ(a.roughness, b.roughness);
      EXPECT_EQ(a.specular, b.specular);
      EXPECT_EQ(a.layered, b.layered);
      EXPECT_EQ(a.retro_diffuse, b.retro_diffuse);
      EXPECT_EQ(a.multiscatter, b.multiscatter);
      break;
  }
  EXPECT_EQ(a.program, b.program);
  if (a.program >= 0) {
    EXPECT_EQ(a.program_displaces, b.program_displaces);
    EXPECT_EQ(a.program_shades, b.program_shades);
    EXPECT_EQ(a.program_alpha, b.program_alpha);
    EXPECT_EQ(a.program_alpha_cut, b.program_alpha_cut);
    EXPECT_EQ(a.displacement_bound, b.displacement_bound);
    EXPECT_EQ(a.displacement_bound_world, b.displacement_bound_world);
  }
}

// Bit for bit (EXPECT_EQ takes -0 for 0).
void expect_same_bits(float a, float b) {
  EXPECT_EQ(a, b);
  EXPECT_EQ(std::signbit(a), std::signbit(b)) << a << " " << b;
}

void expect_same_light(const Light& a, const Light& b) {
  EXPECT_EQ(a.type, b.type);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.intensity, b.intensity);
  if (a.type == Light::Type::Ambient) {
    EXPECT_FALSE(b.cast_shadows);  // ambient light has no shadows to cast
    return;
  }
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.cast_shadows, b.cast_shadows);
  // The size for soft shadows, of the types that have one.
  if (a.type == Light::Type::Point || a.type == Light::Type::Spot) {
    expect_same_bits(a.radius, b.radius);
    EXPECT_EQ(a.soft_falloff, b.soft_falloff);
  }
  if (a.type == Light::Type::Distant) expect_same_bits(a.angle, b.angle);
  if (a.type == Light::Type::Point) return;
  // Unit-length directions come back exactly, others normalised.
  if (std::fabs(glm::length(a.direction) - 1.0f) < 1e-6f) {
    EXPECT_EQ(a.direction, b.direction);
  } else {
    const glm::vec3 d = glm::normalize(a.direction);
    EXPECT_NEAR(b.direction.x, d.x, 1e-7f);
    EXPECT_NEAR(b.direction.y, d.y, 1e-7f);
    EXPECT_NEAR(b.direction.z, d.z, 1e-7f);
  }
  if (a.type == Light::Type::Spot) {
    EXPECT_EQ(a.cone_angle, b.cone_angle);
    EXPECT_EQ(a.cone_delta_angle, b.cone_delta_angle);
    EXPECT_EQ(a.beam_distribution, b.beam_distribution);
  }
  if (a.type == Light::Type::Area) {
    EXPECT_EQ(a.shape, b.shape);
    EXPECT_EQ(a.axis_u, b.axis_u);
    EXPECT_EQ(a.size_u, b.size_u);
    EXPECT_EQ(a.size_v, b.size_v);
  }
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  SCOPED_TRACE("mesh '" + a.name + "'");
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.scheme, b.scheme);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.motion_points, b.motion_points);
  EXPECT_EQ(a.motion_object_to_world, b.motion_object_to_world);
  EXPECT_EQ(a.face_vertex_counts, b.face_vertex_counts);
  EXPECT_EQ(a.face_vertex_indices, b.face_vertex_indices);  // same winding: same front side
  if (a.scheme == SubdivScheme::CatmullClark) {
    EXPECT_EQ(a.crease_vertices, b.crease_vertices);
    EXPECT_EQ(a.crease_sharpness, b.crease_sharpness);
    EXPECT_EQ(a.corner_vertices, b.corner_vertices);
    EXPECT_EQ(a.corner_sharpness, b.corner_sharpness);
    EXPECT_EQ(a.hole_faces, b.hole_faces);
    EXPECT_EQ(a.boundary, b.boundary);
  }
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.face_materials, b.face_materials);
  EXPECT_EQ(a.object_to_world, b.object_to_world);
  EXPECT_EQ(a.double_sided, b.double_sided);
  EXPECT_EQ(a.visible_camera, b.visible_camera);
  EXPECT_EQ(a.cast_shadows, b.cast_shadows);
  EXPECT_TRUE(a.info == b.info) << a.name;
  EXPECT_EQ(a.uv_layers, b.uv_layers);
  EXPECT_EQ(a.corner_normals, b.corner_normals);
  EXPECT_EQ(a.texspace_location, b.texspace_location);
  EXPECT_EQ(a.texspace_size, b.texspace_size);
}

void expect_same_images(const std::vector<Image>& a, const std::vector<Image>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("image '" + a[i].name + "'");
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].width, b[i].width);
    EXPECT_EQ(a[i].height, b[i].height);
    EXPECT_EQ(a[i].pixels, b[i].pixels);  // bit for bit, row order included
    EXPECT_EQ(a[i].srgb, b[i].srgb);
  }
}

void expect_same_scene(const Scene& a, const Scene& b) {
  expect_same_settings(a.settings, b.settings);
  EXPECT_EQ(a.motion_steps, b.motion_steps);
  EXPECT_EQ(a.shutter_curve, b.shutter_curve);
  EXPECT_EQ(a.camera.motion_world_to_camera, b.camera.motion_world_to_camera);
  expect_same_camera(a.camera, b.camera);
  if (a.materials.empty()) {
    // Rendered with Material{}, which comes back as material 0.
    ASSERT_EQ(b.materials.size(), 1u);
    expect_same_material(Material{}, b.materials[0]);
  } else {
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t i = 0; i < a.materials.size(); ++i) expect_same_material(a.materials[i], b.materials[i]);
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    SCOPED_TRACE("light " + std::to_string(i));
    expect_same_light(a.lights[i], b.lights[i]);
  }
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) expect_same_mesh(a.meshes[i], b.meshes[i]);
  expect_same_images(a.images, b.images);
  ASSERT_EQ(a.material_programs.size(), b.material_programs.size());
  for (size_t i = 0; i < a.material_programs.size(); ++i)
    EXPECT_EQ(a.material_programs[i].source, b.material_programs[i].source);
  ASSERT_EQ(a.bezier_patches.size(), b.bezier_patches.size());
  for (size_t i = 0; i < a.bezier_patches.size(); ++i) {
    const BezierPatches &p = a.bezier_patches[i], &q = b.bezier_patches[i];
    SCOPED_TRACE("patch set '" + p.name + "'");
    EXPECT_EQ(p.name, q.name);
    EXPECT_EQ(p.control_points, q.control_points);
    EXPECT_EQ(p.material, q.material);
    EXPECT_EQ(p.object_to_world, q.object_to_world);
    EXPECT_EQ(p.double_sided, q.double_sided);
    EXPECT_EQ(p.visible_camera, q.visible_camera);
    EXPECT_EQ(p.cast_shadows, q.cast_shadows);
    EXPECT_TRUE(p.info == q.info) << p.name;
  }
}

// --- scenes -----------------------------------------------------------------------

Material material(const char* name, Material::Model model, glm::vec3 color) {
  Material m;
  m.name = name;
  m.model = model;
  m.color = color;
  return m;
}

// A bumpy 4x4 Bezier net over [x0, x0+2] x [-1, 1].
std::vector<glm::vec3> bezier_net(float x0, float bump) {
  std::vector<glm::vec3> cps;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      cps.push_back({x0 + 2.0f * i / 3.0f, -1.0f + 2.0f * j / 3.0f, (i % 3 && j % 3) ? bump : 0.0f});
  return cps;
}

// Every Scene feature, in view of a perspective camera, with values that do
// not print exactly in decimal (0.1, 1/3, ...).
Scene full_scene() {
  Scene s;
  RenderSettings& st = s.settings;
  st.width = 64;
  st.height = 48;
  st.pixel_aspect = 1.1f;
  st.crop_x0 = 0.05f, st.crop_x1 = 0.9f, st.crop_y0 = 1.0f / 3.0f, st.crop_y1 = 0.95f;
  st.samples_x = 2, st.samples_y = 2;
  st.shading_rate = 0.7f;
  st.filter = PixelFilter::BlackmanHarris;
  st.filter_width = 3.3f;
  st.bound_split = BoundSplitMethod::Breadth;
  st.bound_split_memory_mib = 48.5f;
  st.max_grid_size = 12;
  st.max_split_depth = 22;
  st.backface_culling = true;
  st.depth_and_normal_passes = false;
  st.shadow_memory_mib = 100.3f;  // shadows stay on, so that the render tests see them
  st.shadow_shading_rate = 2.7f;
  st.occlusion_culling = false;
  st.sample_culling = false;
  st.holdout_covers = true;
  st.visibility_first = VisibilityFirst::Off;
  st.resolver = Resolver::Tiles;
  st.occlusion_waves = OcclusionWaves::On;
  st.bound_split_chain = 5;
  st.bound_split_steps = 3;

  s.camera = look_at({1.3f, 2.1f, 7.7f}, {0.1f, 0.2f, 0.0f}, 47.3f);
  s.camera.screen_left = -1.4f, s.camera.screen_right = 1.3f;
  s.camera.screen_bottom = -0.9f, s.camera.screen_top = 1.1f;
  s.camera.clip_near = 0.1f, s.camera.clip_far = 123.4f;

  // Material 0 is not RenderMan's default; 4 repeats 1 under another name;
  // 6 is unused.
  s.materials.push_back(material("base", Material::Model::Matte, {0.7f, 0.6f, 0.5f}));
  s.materials[0].ka = 0.3f, s.materials[0].kd = 0.9f;
  Material plastic = material("red plastic", Material::Model::Plastic, {0.9f, 0.1f, 0.1f});
  plastic.ka = 0.2f, plastic.kd = 0.6f, plastic.ks = 0.7f, plastic.roughness = 0.05f;
  plastic.specular_color = {1.0f, 0.9f, 0.8f};
  plastic.emission = {0.01f, 0.0f, 0.02f};
  s.materials.push_back(plastic);
  Material principled = material("gold", Material::Model::Principled, {1.0f, 0.766f, 0.336f});
  principled.metallic = 0.9f, principled.roughness = 0.35f, principled.specular = 0.45f;
  principled.layered = true;
  principled.multiscatter = true;
  principled.opacity = glm::vec3(0.75f);
  s.materials.push_back(principled);
  Material glow = material("glow", Material::Model::Constant, {0.2f, 0.3f, 0.4f});
  glow.emission = {0.5f, 0.25f, 0.125f};
  s.materials.push_back(glow);
  Material twin = plastic;
  twin.name = "red plastic copy";
  s.materials.push_back(twin);
  Material rough = material("rough principled", Material::Model::Principled, {0.2f, 0.5f, 0.3f});
  rough.roughness = 0.8f, rough.specular = 0.6f, rough.emission = {0.0f, 0.05f, 0.0f};
  s.materials.push_back(rough);
  s.materials.push_back(material("unused", Material::Model::Matte, {0.1f, 0.2f, 0.3f}));

  Light ambient;
  ambient.type = Light::Type::Ambient;
  ambient.intensity = 0.15f;
  ambient.color = {0.9f, 0.95f, 1.0f};
  s.lights.push_back(ambient);
  Light sun;
  sun.type = Light::Type::Distant;
  sun.intensity = 0.8f;
  sun.position = {3.0f, 9.0f, 1.0f};
  sun.direction = glm::normalize(glm::vec3(-0.3f, -0.5f, -1.0f));
  sun.angle = 0.0093f;
  s.lights.push_back(sun);
  Light point;
  point.type = Light::Type::Point;
  point.position = {-2.5f, 3.1f, 2.2f};
  point.intensity = 9.0f;
  point.color = {1.0f, 0.8f, 0.6f};
  point.radius = 0.3f;
  point.soft_falloff = false;
  s.lights.push_back(point);
  Light spot;
  spot.type = Light::Type::Spot;
  spot.position = {0.3f, 5.0f, 40.0f};  // far away: the direction must stay accurate
  spot.direction = glm::vec3(0.0f, -5.0f, -40.0f);  // not normalised
  spot.intensity = 900.0f;
  spot.cone_angle = 0.2f, spot.cone_delta_angle = 0.05f, spot.beam_distribution = 1.5f;
  spot.radius = 1.0f / 3.0f;
  s.lights.push_back(spot);
  Light rect;
  rect.type = Light::Type::Area;
  rect.shape = Light::Shape::Rectangle;
  rect.position = {0.5f, 3.0f, 1.5f};
  rect.direction = glm::normalize(glm::vec3(0.1f, -1.0f, -0.2f));
  rect.axis_u = {1.0f, 0.1f, 0.0f};
  rect.size_u = 1.5f, rect.size_v = 0.7f;
  rect.intensity = 2.5f;
  rect.color = {0.6f, 0.7f, 1.0f};
  s.lights.push_back(rect);
  Light disk = rect;
  disk.shape = Light::Shape::Ellipse;
  disk.position = {-1.0f, 0.5f, 3.0f};
  disk.direction = {0.2f, 0.0f, -1.0f};
  disk.axis_u = {0.0f, 1.0f, 0.0f};
  disk.size_u = 0.9f, disk.size_v = 1.3f;
  disk.cast_shadows = false;
  s.lights.push_back(disk);

  // Catmull-Clark cube: creases, corners, a hole, edge-only boundary, a
  // per-face material and a rotation.
  Mesh cube = cube_mesh(SubdivScheme::CatmullClark);
  cube.name = "subdiv cube";
  cube.crease_vertices = {0, 1, 1, 2, 4, 5};
  cube.crease_sharpness = {2.5f, 10.0f, 0.3f};
  cube.corner_vertices = {6, 7};
  cube.corner_sharpness = {1.7f, 4.0f};
  cube.hole_faces = {3};
  cube.boundary = BoundaryInterpolation::EdgeOnly;
  cube.material = 1;
  cube.face_materials = {1, 1, 2, 1, 5, 1};
  cube.object_to_world = glm::rotate(glm::scale(glm::mat4(1.0f), glm::vec3(0.6f)), 0.4f, glm::vec3(0.2f, 1.0f, 0.1f));
  s.meshes.push_back(cube);

  // Polygon floor with several face materials, single-sided.
  Mesh floor = grid_mesh(3, 2.5f, SubdivScheme::None);
  floor.name = "floor";
  floor.material = 0;
  floor.face_materials = {0, 2, 0, 5, 0, 2, 1, 0, 4};
  floor.object_to_world = glm::translate(glm::rotate(glm::mat4(1.0f), -1.2f, glm::vec3(1, 0, 0)), glm::vec3(0, 0, -0.8f));
  floor.double_sided = false;
  s.meshes.push_back(floor);

  // Mirrored (negative determinant), single-sided: the same faces stay front.
  Mesh mirrored = cube_mesh(SubdivScheme::None);
  mirrored.name = "mirrored";
  mirrored.material = 3;
  mirrored.double_sided = false;
  mirrored.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(-1.8f, 0.3f, 0.5f)), glm::vec3(-0.3f, 0.4f, 0.35f));
  mirrored.cast_shadows = false;
  mirrored.info = {{0.9f, 0.4f, 0.3f, 1.0f}, 7.0f, 0.25f};  // Object Info's values
  s.meshes.push_back(mirrored);

  // Catmull-Clark with the other boundary modes and a pentagon.
  Mesh sheet = grid_mesh(2, 0.5f, SubdivScheme::CatmullClark);
  sheet.name = "";  // an empty name stays empty
  sheet.boundary = BoundaryInterpolation::None;
  sheet.material = 2;
  sheet.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(1.6f, 0.9f, 0.4f));
  s.meshes.push_back(sheet);
  Mesh sheet2 = sheet;
  sheet2.name = "corner sheet";
  sheet2.boundary = BoundaryInterpolation::EdgeAndCorner;
  sheet2.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(1.6f, -0.5f, 0.4f));
  sheet2.visible_camera = false;  // hidden from the camera, still casting shadows
  s.meshes.push_back(sheet2);
  Mesh pentagon;
  pentagon.name = "pentagon";
  for (int i = 0; i < 5; ++i) {
    const float a = 0.3f + 1.2566371f * i;
    pentagon.points.push_back({1.9f + 0.4f * std::cos(a), 1.6f + 0.4f * std::sin(a), 0.2f});
  }
  pentagon.points.push_back({9.0f, 9.0f, 9.0f});  // unused points are kept
  pentagon.face_vertex_counts = {5};
  pentagon.face_vertex_indices = {0, 1, 2, 3, 4};
  pentagon.material = 4;
  s.meshes.push_back(pentagon);

  // Two patch sets with identical state: they must stay two sets.
  BezierPatches patches;
  patches.name = "patches";
  patches.control_points = bezier_net(-2.6f, 0.8f);
  const std::vector<glm::vec3> second = bezier_net(-0.6f, -0.5f);
  patches.control_points.insert(patches.control_points.end(), second.begin(), second.end());
  patches.material = 5;
  patches.double_sided = false;
  patches.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, -1.1f, 1.0f));
  s.bezier_patches.push_back(patches);
  patches.control_points = bezier_net(1.4f, 0.3f);
  s.bezier_patches.push_back(patches);
  BezierPatches mirrored_patch;
  mirrored_patch.name = "mirrored patch";
  mirrored_patch.control_points = bezier_net(0.0f, 0.6f);
  mirrored_patch.material = 2;
  mirrored_patch.object_to_world = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, 1.8f, 0.0f)), glm::vec3(-0.5f, 0.5f, 0.5f));
  mirrored_patch.visible_camera = false;
  mirrored_patch.cast_shadows = false;
  mirrored_patch.info = {{0.2f, 0.7f, 0.1f, 0.5f}, 3.0f, 0.8125f};  // Object Info's values
  s.bezier_patches.push_back(mirrored_patch);

  // Texturing: a material program reads two UV layers, two images (one sRGB
  // encoded, one linear, both asymmetric so a flipped row order shows) and
  // Generated coordinates with an explicit texture space.
  Image checker{"checker \"sRGB\"", 5, 3, {}, true};
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      checker.pixels.push_back({((x + y) % 2) ? 0.9f : 0.1f, x / 4.0f, y / 3.0f, 1.0f - 0.1f * x});
  s.images.push_back(checker);
  Image ramp{"linear ramp", 4, 2, {}, false};
  for (int i = 0; i < 8; ++i) ramp.pixels.push_back({0.1f * i, 2.5f - 0.3f * i, 1.0f / 3.0f, 1.0f});
  s.images.push_back(ramp);
  s.material_programs.push_back(
      {"textured",
       "#include \"textures/mp_tex_image.h\"\n"
       "float3 mp_node_displacement(const MpNodeGlobals* g) { return (float3)(0.0f); }\n"
       "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {\n"
       "  float4 a = mp_tex_image(g->images, g->image_count, g->texels, 0, g->uv[0].x, g->uv[0].y, 0, 0);\n"
       "  float4 b = mp_tex_image(g->images, g->image_count, g->texels, 1, g->uv[1].x, g->uv[1].y, 1, 1);\n"
       "  mp_add_emission(s, a.xyz * 0.6f + b.xyz * 0.2f + g->generated * 0.2f); }\n"});
  Material textured = material("textured", Material::Model::Principled, glm::vec3(0.5f));
  textured.program = 0;
  textured.program_shades = true;
  textured.program_alpha = true;
  textured.displacement_bound = 0.25f;
  textured.displacement_bound_world = true;  // written and read back, though this program does not displace
  s.materials.push_back(textured);
  const int textured_index = static_cast<int>(s.materials.size()) - 1;
  for (const char* name : {"floor", "corner sheet"}) {
    Mesh& m = *std::find_if(s.meshes.begin(), s.meshes.end(), [&](const Mesh& x) { return x.name == name; });
    std::vector<glm::vec2> uv0, uv1;
    for (size_t c = 0; c < m.face_vertex_indices.size(); ++c) {
      const glm::vec3 p = m.points[static_cast<size_t>(m.face_vertex_indices[c])];
      uv0.push_back(glm::vec2(p.x, p.y) * 0.37f + glm::vec2(0.1f, 1.0f / 3.0f));
      uv1.push_back({0.05f * static_cast<float>(c % 7), p.y * 0.3f});  // discontinuous per corner
    }
    m.uv_layers = {uv0, uv1};
    m.material = textured_index;
    m.face_materials.clear();
  }
  // Smooth shading normals on two polygon meshes (one an n-gon).
  for (const char* name : {"floor", "pentagon"}) {
    Mesh& m = *std::find_if(s.meshes.begin(), s.meshes.end(), [&](const Mesh& x) { return x.name == name; });
    for (size_t c = 0; c < m.face_vertex_indices.size(); ++c)
      m.corner_normals.push_back(glm::normalize(glm::vec3(0.1f * float(c % 5), -0.2f, 1.0f)));
  }
  s.meshes[0].texspace_location = {0.1f, -0.2f, 0.3f};
  s.meshes[0].texspace_size = {1.1f, 0.9f, 1.0f / 3.0f};
  s.meshes[0].face_materials = {1, 1, textured_index, 1, 5, textured_index};
  validate_scene(s);
  return s;
}

// An orthographic camera with an explicit screen window, near plane 0, no
// materials (Material{} is used), default settings otherwise.
Scene ortho_scene() {
  Scene s;
  s.settings.width = 64;
  s.settings.height = 48;
  s.settings.samples_x = s.settings.samples_y = 2;
  s.settings.filter = PixelFilter::Triangle;
  s.settings.filter_width = 1.5f;
  s.camera = look_at({0.0f, 0.0f, 10.0f}, {0.0f, 0.0f, 0.0f});
  s.camera.projection = Camera::Projection::Orthographic;
  s.camera.fov_degrees = 30.0f;  // unused by orthographic cameras
  s.camera.screen_left = -2.2f, s.camera.screen_right = 2.0f;
  s.camera.screen_bottom = -1.3f, s.camera.screen_top = 1.7f;
  s.camera.clip_near = 0.0f;
  Light key;
  key.type = Light::Type::Distant;
  key.direction = {-0.2f, -0.3f, -1.0f};
  s.lights.push_back(key);
  Mesh cube = cube_mesh(SubdivScheme::CatmullClark);
  cube.object_to_world = glm::rotate(glm::mat4(1.0f), 0.6f, glm::vec3(1.0f, 1.0f, 0.0f));
  s.meshes.push_back(cube);
  s.settings.crop_x0 = 0.25f;
  return s;
}

// --- tests ---------------------------------------------------------------------------

TEST(RibWriter, FullSceneRoundTripsFieldByField) {
  const Scene s = full_scene();
  expect_same_scene(s, round_trip(s));
}

TEST(RibWriter, OrthographicSceneWithoutMaterialsRoundTrips) {
  const Scene s = ortho_scene();
  expect_same_scene(s, round_trip(s));
}

TEST(RibWriter, DefaultSceneRoundTrips) {
  Scene s;
  s.meshes.push_back(polygon({{0, 0, -2}, {1, 0, -2}, {0, 1, -2}}));
  expect_same_scene(s, round_trip(s));
}

TEST(RibWriter, EveryFilterAndBoundSplitMethod) {
  for (PixelFilter f : {PixelFilter::Box, PixelFilter::Gaussian, PixelFilter::Triangle, PixelFilter::BlackmanHarris})
    for (BoundSplitMethod m : {BoundSplitMethod::Bounded, BoundSplitMethod::Breadth}) {
      Scene s = ortho_scene();
      s.settings.filter = f;
      s.settings.bound_split = m;
      s.settings.backface_culling = false;
      s.settings.depth_and_normal_passes = true;
      expect_same_settings(s.settings, round_trip(s).settings);
    }
}

TEST(RibWriter, ShadowFieldsOfEveryLightType) {
  // Every light type with and without shadows, with sizes that print
  // inexactly and a negative zero, which must come back as such.
  for (Light::Type type : {Light::Type::Ambient, Light::Type::Distant, Light::Type::Point, Light::Type::Spot,
                           Light::Type::Area})
    for (bool casts : {true, false})
      for (float size : {0.1f, -0.0f, 0.0f}) {
        SCOPED_TRACE("type " + std::to_string(static_cast<int>(type)) + (casts ? " casting" : "") + " size " +
                     std::to_string(size));
        Scene s = ortho_scene();
        Light l;
        l.type = type;
        l.position = {0.5f, 2.0f, 1.0f};
        l.direction = {0.0f, -1.0f, 0.0f};
        l.cast_shadows = casts;
        l.radius = size;
        l.angle = size;
        l.soft_falloff = size != 0.1f;
        s.lights = {l};
        const Scene back = round_trip(s);
        ASSERT_EQ(back.lights.size(), 1u);
        expect_same_light(l, back.lights[0]);
        // Sizes a type does not have come back as the defaults.
        const Light def;
        if (type != Light::Type::Point && type != Light::Type::Spot) {
          EXPECT_EQ(back.lights[0].radius, def.radius);
          EXPECT_EQ(back.lights[0].soft_falloff, def.soft_falloff);
        }
        if (type != Light::Type::Distant) EXPECT_EQ(back.lights[0].angle, def.angle);
      }
}

TEST(RibWriter, ShadowExtensionsOnlyWhereNotDefault) {
  // A default scene stays standard RIB but for the shadow name, which is
  // RenderMan's own way to ask for shadows.
  Scene s;
  s.lights.push_back(Light{});
  s.meshes.push_back(polygon({{0, 0, -2}, {1, 0, -2}, {0, 1, -2}}));
  Material m;
  m.program = 0;
  s.materials.push_back(m);
  s.material_programs.push_back({"p", "void f() {}"});
  std::string text = to_rib(s);
  EXPECT_NE(text.find("\"string shadowname\" [\"raytrace\"]"), std::string::npos) << text;
  for (const char* name : {"micropoly:radius", "micropoly:softfalloff", "micropoly:angle", "visibility",
                           "integer shadows", "shadowmemory", "shadowshadingrate", "programalpha"})
    EXPECT_EQ(text.find(name), std::string::npos) << name << "\n" << text;
  expect_same_scene(s, round_trip(s));

  // Each one written when set, and read back.
  s.lights[0].cast_shadows = false;
  s.settings.shadows = false;
  s.settings.shadow_memory_mib = 0.1f;
  s.settings.shadow_shading_rate = 16.5f;
  s.materials[0].program_alpha = true;
  s.meshes[0].visible_camera = false;
  text = to_rib(s);
  EXPECT_EQ(text.find("shadowname"), std::string::npos) << text;
  for (const char* written : {"\"integer shadows\" [0]", "\"float shadowmemory\" [0.1]",
                              "\"float shadowshadingrate\" [16.5]", "\"integer programalpha\" [1]",
                              "Attribute \"visibility\" \"int camera\" [0] \"int transmission\" [1]"})
    EXPECT_NE(text.find(written), std::string::npos) << written << "\n" << text;
  expect_same_scene(s, round_trip(s));
  s.meshes[0].visible_camera = true;
  s.meshes[0].cast_shadows = false;
  text = to_rib(s);
  EXPECT_NE(text.find("Attribute \"visibility\" \"int camera\" [1] \"int transmission\" [0]"), std::string::npos);
  expect_same_scene(s, round_trip(s));
  // A hard cut's alpha (Material::program_alpha_cut) travels as programalpha 2.
  s.materials[0].program_alpha_cut = true;
  text = to_rib(s);
  EXPECT_NE(text.find("\"integer programalpha\" [2]"), std::string::npos) << text;
  EXPECT_TRUE(round_trip(s).materials[0].program_alpha_cut);
  expect_same_scene(s, round_trip(s));
}

TEST(RibWriter, FloatsReadBackExactly) {
  // Awkward values: many digits, tiny, huge, denormal, negative zero.
  // (Points stop at 1e15, validation's world limit; the largest finite
  // float goes through the camera's far clipping distance.)
  const float values[] = {0.1f, 1.0f / 3.0f, 2.0f / 3.0f, 3.14159274f, 1e-7f, 1.17549435e-38f,
                          1e-40f, 9.99999987e14f, -123456.789f, 16777217.0f, -0.0f, 0.30000001f};
  Scene s;
  s.camera.clip_far = 3.40282347e38f;
  Mesh m = polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  for (float v : values) m.points.push_back({v, -v, v * 0.5f});
  for (int i = 0; i < 1000; ++i) {
    // Pseudo-random floats over many binades.
    const float v = std::ldexp(static_cast<float>((i * 2654435761u) % 16777216u) / 16777216.0f + 0.5f, (i % 60) - 30);
    m.points.push_back({v, 1.0f / (v + 1.0f), -v * 7.0f});
  }
  s.meshes.push_back(m);
  const Scene back = round_trip(s);
  EXPECT_EQ(back.meshes.at(0).points, m.points);
  EXPECT_EQ(back.camera.clip_far, s.camera.clip_far);
}

TEST(RibWriter, NamesAreEscaped) {
  // Quotes, backslashes, newlines, tabs, other control characters, UTF-8
  // and a byte that is not UTF-8 all come back; the file stays valid.
  const std::string names[] = {"say \"hi\"", "back\\slash\\", "two\nlines\r\n", "tab\there",
                               std::string("bell\x07 del\x7f esc\x1b"), "caf\xc3\xa9 \xe2\x82\xac",
                               std::string("bad \xff\xc3 byte"), "\\\"\\n", "# not a comment [ ]"};
  Scene s;
  for (const std::string& name : names) {
    Mesh m = polygon({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    m.name = name;
    s.meshes.push_back(m);
    Material mat;
    mat.name = name;
    s.materials.push_back(mat);
  }
  const Scene back = round_trip(s);
  ASSERT_EQ(back.meshes.size(), s.meshes.size());
  for (size_t i = 0; i < s.meshes.size(); ++i) {
    EXPECT_EQ(back.meshes[i].name, s.meshes[i].name);
    EXPECT_EQ(back.materials[i].name, s.materials[i].name);
  }
  // Raw control characters never reach the file.
  const std::string text = to_rib(s);
  for (char c : text) EXPECT_TRUE(c == '\n' || static_cast<unsigned char>(c) >= 0x20) << int(c);
}

TEST(RibWriter, DisplayNameAndFileErrors) {
  Scene s = ortho_scene();
  std::ostringstream out;
  write_rib(s, out, "image \"1\".exr");
  const RibResult r = read_rib_string(out.str(), "display.rib");
  EXPECT_EQ(r.display_name, "image \"1\".exr");

  EXPECT_THROW(write_rib_file(s, "/nonexistent-directory/scene.rib"), Error);
  Scene bad = s;
  bad.meshes[0].face_vertex_indices[0] = 99;  // invalid scenes are refused
  EXPECT_THROW(write_rib(bad, out), Error);
  const std::string path = ::testing::TempDir() + "/rib_writer_file.rib";
  write_rib_file(s, path);
  expect_same_scene(s, read_rib_file(path).scene);

  // Texture images: a file gets a folder beside it, named relative to it;
  // a stream needs a folder.
  const Scene textured = full_scene();
  EXPECT_THROW(write_rib(textured, out), Error);
  write_rib_file(textured, path);
  std::ifstream rib(path);
  const std::string text((std::istreambuf_iterator<char>(rib)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"string imagefile\" \"rib_writer_file_textures/1.exr\""), std::string::npos);
  expect_same_scene(textured, read_rib_file(path).scene);
}

// --- the reader's side of the extensions -------------------------------------------------

RibResult parse(const std::string& body) {
  return read_rib_string("WorldBegin\n" + body + "\nWorldEnd\n", "ext.rib");
}

TEST(RibWriterExtensions, MaterialTableIndicesAndNames) {
  const RibResult r = parse(
      "Surface \"plastic\" \"Ks\" 0.25\n"
      "Attribute \"micropoly\" \"integer material\" 0 \"string materialname\" \"zero\"\n"
      "Color [1 0 0]\n"
      "Attribute \"micropoly\" \"integer material\" 1\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Color [0 1 0]\n"  // changes the state: back to a deduplicated material
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n");
  const Scene& s = r.scene;
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].name, "zero");
  EXPECT_EQ(s.materials[0].ks, 0.25f);
  EXPECT_EQ(s.materials[1].name, "plastic");  // the shader name without materialname
  EXPECT_EQ(s.materials[1].color, glm::vec3(1, 0, 0));
  ASSERT_EQ(s.meshes.size(), 2u);
  EXPECT_EQ(s.meshes[0].material, 1);
  EXPECT_EQ(s.meshes[1].material, 2);
  EXPECT_EQ(s.materials[2].color, glm::vec3(0, 1, 0));
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RibWriterExtensions, UVLayersPerVertexPerCornerAndReversed) {
  // Per-vertex UVs are spread to the corners; a reversed orientation reverses
  // each face's corners with their UVs; Polygon runs merged into one mesh
  // keep their UVs, a layer one of them lacks reading zeros.
  const RibResult r = parse(
      "PointsPolygons [3 4] [0 1 2 0 2 3 1] \"P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
      "  \"vertex float[2] micropoly:uv0\" [0 0 1 0 1 1 0 1]\n"
      "  \"facevarying float[2] micropoly:uv1\" [1 1 2 2 3 3 4 4 5 5 6 6 7 7]\n"
      "AttributeBegin\nReverseOrientation\n"
      "SubdivisionMesh \"catmull-clark\" [3] [0 1 2] \"P\" [0 0 0 1 0 0 1 1 0]\n"
      "  \"facevarying float[2] micropoly:uv0\" [0 0 1 0 1 1]\n"
      "  \"constant float[3] micropoly:texspacelocation\" [1 2 3]\n"
      "AttributeEnd\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0]\n"
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0] \"facevarying float[2] micropoly:uv0\" [5 6 7 8 9 10]\n");
  EXPECT_TRUE(r.warnings.empty());
  const Scene& s = r.scene;
  ASSERT_EQ(s.meshes.size(), 3u);
  using V = std::vector<glm::vec2>;
  ASSERT_EQ(s.meshes[0].uv_layers.size(), 2u);
  EXPECT_EQ(s.meshes[0].uv_layers[0], (V{{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}, {1, 0}}));
  EXPECT_EQ(s.meshes[0].uv_layers[1], (V{{1, 1}, {2, 2}, {3, 3}, {4, 4}, {5, 5}, {6, 6}, {7, 7}}));
  EXPECT_EQ(s.meshes[1].face_vertex_indices, (std::vector<int>{2, 1, 0}));
  EXPECT_EQ(s.meshes[1].uv_layers, (std::vector<V>{{{1, 1}, {1, 0}, {0, 0}}}));
  EXPECT_EQ(s.meshes[1].texspace_location, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.meshes[2].uv_layers, (std::vector<V>{{{0, 0}, {0, 0}, {0, 0}, {5, 6}, {7, 8}, {9, 10}}}));
}

TEST(RibWriterExtensions, ShadingNormals) {
  // RenderMan's "N": per vertex on a Polygon, per corner on PointsPolygons
  // (reversed with the face), flat normals filled in for a merged polygon
  // without them, and ignored (with a warning) on a Catmull-Clark mesh.
  const RibResult r = parse(
      "Polygon \"P\" [0 0 0 1 0 0 0 1 0] \"N\" [0 0 1 0 0.6 0.8 0.6 0 0.8]\n"
      "Polygon \"P\" [0 0 1 1 0 1 0 1 1]\n"
      "AttributeBegin\nReverseOrientation\n"
      "PointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"facevarying normal N\" [0 0 1 0 0 2 0 0 3]\n"
      "AttributeEnd\n"
      "SubdivisionMesh \"catmull-clark\" [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"N\" [0 0 1 0 0 1 0 0 1]\n");
  const Scene& s = r.scene;
  ASSERT_EQ(s.meshes.size(), 3u);
  using N = std::vector<glm::vec3>;
  EXPECT_EQ(s.meshes[0].corner_normals, (N{{0, 0, 1}, {0, 0.6f, 0.8f}, {0.6f, 0, 0.8f}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}}));
  EXPECT_EQ(s.meshes[1].corner_normals, (N{{0, 0, 3}, {0, 0, 2}, {0, 0, 1}}));
  EXPECT_TRUE(s.meshes[2].corner_normals.empty());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("\"N\""), std::string::npos);
}

TEST(RibWriterExtensions, PngTexturesAreSrgbAndBottomRowFirst) {
  // A 1 x 2 PNG, red on top: the Scene stores the bottom (blue) row first.
  RenderResult png;
  png.width = 1, png.height = 2;
  png.rgba = {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.2f, 1.0f};
  const std::string dir = ::testing::TempDir();
  write_image(dir + "/rib_texture.png", png);
  const RibResult r = read_rib_string("Option \"micropoly\" \"string imagefile\" \"rib_texture.png\"\n",
                                      dir + "/texture.rib", dir);
  ASSERT_EQ(r.scene.images.size(), 1u);
  const Image& im = r.scene.images[0];
  EXPECT_EQ(im.name, "rib_texture.png");
  EXPECT_TRUE(im.srgb);  // PNGs hold sRGB-encoded values
  ASSERT_EQ(im.pixels.size(), 2u);
  EXPECT_EQ(im.pixels[0], glm::vec4(0.0f, 0.0f, std::round(linear_to_srgb(0.2f) * 255.0f) / 255.0f, 1.0f));
  EXPECT_EQ(im.pixels[1], glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
}

TEST(RibWriterExtensions, MakeTextureNamesItsPictureForLaterImages) {
  // RenderMan's texture file is what every image gets at render time (its
  // MIP levels): an image option naming the texture reads the picture.
  RenderResult png;
  png.width = 3, png.height = 2;
  png.rgba.assign(3 * 2 * 4, 0.5f);
  const std::string dir = ::testing::TempDir();
  write_image(dir + "/make_texture_source.png", png);
  const RibResult r = read_rib_string(
      "MakeTexture \"make_texture_source.png\" \"made.tex\" \"periodic\" \"clamp\" \"gaussian\" 2 2\n"
      "Option \"micropoly\" \"string imagefile\" \"made.tex\"\n",
      dir + "/texture.rib", dir);
  ASSERT_EQ(r.scene.images.size(), 1u);
  EXPECT_EQ(r.scene.images[0].width, 3);
  EXPECT_EQ(r.scene.images[0].height, 2);
  EXPECT_EQ(r.scene.images[0].name, "made.tex");
  // One warning says wrap modes and filters belong to each lookup (the
  // other: the scene has no world block).
  EXPECT_EQ(std::count_if(r.warnings.begin(), r.warnings.end(),
                          [](const std::string& w) { return w.find("come from each lookup") != std::string::npos; }),
            1);
  // A wrap mode RenderMan does not have is an error.
  EXPECT_THROW(read_rib_string("MakeTexture \"make_texture_source.png\" \"m.tex\" \"repeat\" \"clamp\" "
                               "\"box\" 1 1\n",
                               dir + "/texture.rib", dir),
               RibError);
}

TEST(RibWriterExtensions, ShadowOptionsAndProgramAlpha) {
  const RibResult r = read_rib_string(
      "Option \"micropoly\" \"integer shadows\" [0] \"float shadowmemory\" [32.5] \"float shadowshadingrate\" [0.5]\n"
      "Option \"micropoly\" \"integer occlusionculling\" [0] \"integer holdoutcovers\" [1]\n"
      "WorldBegin\n"
      "Attribute \"micropoly\" \"integer material\" 1 \"string program\" \"a\" \"integer programalpha\" 1\n"
      "Attribute \"micropoly\" \"integer material\" 2 \"string program\" \"a\" \"integer programshades\" 1\n"
      "WorldEnd\n",
      "ext.rib");
  EXPECT_TRUE(r.warnings.empty());
  const Scene& s = r.scene;
  EXPECT_FALSE(s.settings.shadows);
  EXPECT_EQ(s.settings.shadow_memory_mib, 32.5f);
  EXPECT_EQ(s.settings.shadow_shading_rate, 0.5f);
  EXPECT_FALSE(s.settings.occlusion_culling);
  EXPECT_TRUE(s.settings.holdout_covers);
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_TRUE(s.materials[1].program_alpha);
  EXPECT_FALSE(s.materials[2].program_alpha);  // the default
  EXPECT_TRUE(s.materials[2].program_shades);
  // Without the option the Scene's defaults stay.
  const RenderSettings def;
  const Scene plain = parse("").scene;
  EXPECT_EQ(plain.settings.shadows, def.shadows);
  EXPECT_EQ(plain.settings.shadow_memory_mib, def.shadow_memory_mib);
  EXPECT_EQ(plain.settings.shadow_shading_rate, def.shadow_shading_rate);
  EXPECT_EQ(plain.settings.occlusion_culling, def.occlusion_culling);
  EXPECT_EQ(plain.settings.holdout_covers, def.holdout_covers);
}

TEST(RibWriterExtensions, BadValuesAreErrors) {
  auto expect_error = [](const std::string& text, const std::string& fragment) {
    try {
      read_rib_string(text, "bad.rib");
      ADD_FAILURE() << "no error for: " << text;
    } catch (const RibError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("WorldBegin\nAttribute \"micropoly\" \"integer material\" 2\nWorldEnd\n", "material");
  expect_error("WorldBegin\nPointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] "
               "\"uniform integer micropoly:material\" [1]\nWorldEnd\n",
               "micropoly:material");
  expect_error("WorldBegin\nPointsPolygons [3 3] [0 1 2 0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] "
               "\"uniform integer micropoly:material\" [0]\nWorldEnd\n",
               "one material index per face");
  expect_error("Option \"micropoly\" \"string boundsplit\" \"fast\"\n", "boundsplit");
  expect_error("Option \"micropoly\" \"integer backfaceculling\" 2\n", "backfaceculling");
  expect_error("Option \"micropoly\" \"integer occlusionculling\" 2\n", "occlusionculling");
  expect_error("WorldBegin\nLightSource \"micropoly_arealight\" 1 \"string shape\" \"disc\"\nWorldEnd\n", "shape");
  expect_error("Option \"micropoly\" \"string imagefile\" \"/nonexistent/t.exr\"\n", "/nonexistent/t.exr");
  expect_error("Option \"micropoly\" \"string imagefile\" \"t.tif\"\n", "only .exr and .png");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0] \"facevarying float[2] micropoly:uv0\" [0 0 1 0]\nWorldEnd\n",
               "micropoly:uv0");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0] \"constant float[2] micropoly:texspacesize\" [1 1]\nWorldEnd\n",
               "texspacesize");
  expect_error("WorldBegin\nPointsPolygons [3] [0 1 2] \"P\" [0 0 0 1 0 0 0 1 0] \"facevarying normal N\" [0 0 1 0 0 1]\nWorldEnd\n",
               "\"N\" needs one normal per vertex");
  expect_error("WorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0] \"uniform normal N\" [0 0 1]\nWorldEnd\n", "\"N\"");
}

TEST(RibWriterExtensions, EnvironmentLightRoundTrips) {
  // A world map given as radiance: written as a texture beside the RIB and
  // read back texel for texel, with its visibility and shadow settings.
  Scene s;
  s.settings.world_probes = 5;
  World& w = s.world;
  w.width = 8, w.height = 4;
  for (int i = 0; i < w.width * w.height; ++i) w.radiance.insert(w.radiance.end(), {0.1f * i, 1.0f, 2.5f, 1.0f});
  w.camera = false, w.diffuse = 0.5f, w.glossy = 0.25f, w.cast_shadows = false;
  const Scene back = round_trip(s);
  EXPECT_EQ(back.settings.world_probes, 5);
  EXPECT_EQ(back.world.program, -1);
  EXPECT_EQ(back.world.width, 8);
  EXPECT_EQ(back.world.height, 4);
  EXPECT_EQ(back.world.radiance, w.radiance);
  EXPECT_FALSE(back.world.camera);
  EXPECT_EQ(back.world.diffuse, 0.5f);
  EXPECT_EQ(back.world.glossy, 0.25f);
  EXPECT_FALSE(back.world.cast_shadows);
  // A world program travels as its source, shared with a material's.
  Scene p;
  p.material_programs.push_back({"world", "/* the world's program */\n"});
  p.world.program = 0, p.world.bake_width = 256;
  const Scene pb = round_trip(p);
  ASSERT_EQ(pb.material_programs.size(), 1u);
  EXPECT_EQ(pb.material_programs[0].source, p.material_programs[0].source);
  EXPECT_EQ(pb.world.program, 0);
  EXPECT_EQ(pb.world.bake_width, 256);
  EXPECT_TRUE(pb.world.camera);
  EXPECT_TRUE(pb.world.cast_shadows);
  // Exactly one of "program" and "mapname".
  EXPECT_THROW(read_rib_string("WorldBegin\nLightSource \"micropoly_environmentlight\" 1\nWorldEnd\n", "e.rib"),
               RibError);
  EXPECT_THROW(read_rib_string("WorldBegin\nLightSource \"micropoly_environmentlight\" 1 \"string mapname\" "
                               "\"/nonexistent/sky.exr\"\nWorldEnd\n", "e.rib"),
               RibError);
}

TEST(RibWriterExtensions, AreaLightInCameraSpace) {
  // Declared before WorldBegin: carried to world space like the standard lights.
  const RibResult r = read_rib_string(
      "LightSource \"micropoly_arealight\" 1 \"from\" [0 0 0] \"to\" [0 0 1] \"vector axis\" [0 1 0] "
      "\"string shape\" \"ellipse\" \"float width\" 2 \"float height\" 3\n"
      "Translate 0 0 5\nWorldBegin\nPolygon \"P\" [0 0 0 1 0 0 0 1 0]\nWorldEnd\n",
      "area.rib");
  ASSERT_EQ(r.scene.lights.size(), 1u);
  const Light& l = r.scene.lights[0];
  EXPECT_EQ(l.type, Light::Type::Area);
  EXPECT_EQ(l.shape, Light::Shape::Ellipse);
  EXPECT_EQ(l.position, glm::vec3(0, 0, -5));
  EXPECT_EQ(l.direction, glm::vec3(0, 0, 1));
  EXPECT_EQ(l.axis_u, glm::vec3(0, 1, 0));
  EXPECT_EQ(l.size_u, 2.0f);
  EXPECT_EQ(l.size_v, 3.0f);
}

// --- rendering: the round-tripped scene gives the same image ---------------------------

class RibWriterRender : public SharedRendererTest {
 protected:

  // Max abs difference over every channel of the two renders.
  static float max_difference(const Scene& scene) {
    const Scene back = round_trip(scene);
    const RenderResult a = renderer_->render(scene);
    const RenderResult b = renderer_->render(back);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.rgba.size(), b.rgba.size());
    float diff = 0.0f, sum = 0.0f;
    for (size_t i = 0; i < std::min(a.rgba.size(), b.rgba.size()); ++i) {
      diff = std::max(diff, std::fabs(a.rgba[i] - b.rgba[i]));
      sum += a.rgba[i];
    }
    EXPECT_GT(sum, 0.0f) << "the test scene renders nothing";
    return diff;
  }
};

TEST_F(RibWriterRender, FullSceneRendersTheSame) {
  Scene s = full_scene();
  set_samples_per_pixel(s.settings, 4);
  EXPECT_LE(max_difference(s), 1.0f / 255.0f);
}

TEST_F(RibWriterRender, FullSceneWithoutCropRendersTheSame) {
  Scene s = full_scene();
  s.settings.crop_x0 = s.settings.crop_y0 = 0.0f;
  s.settings.crop_x1 = s.settings.crop_y1 = 1.0f;
  s.settings.filter = PixelFilter::Gaussian;
  s.settings.filter_width = 2.0f;
  s.settings.bound_split = BoundSplitMethod::Bounded;
  EXPECT_LE(max_difference(s), 1.0f / 255.0f);
}

// Depth of field travels as DepthOfField (radius = focallength / 2 fstop)
// and the aperture's shape as Option "micropoly"; the image is the same.
Scene defocused_scene() {
  Scene s = full_scene();
  s.camera.lens_radius = 0.37f;
  s.camera.focus_distance = 4.3f;
  s.camera.aperture_blades = 5;
  s.camera.aperture_rotation = 0.3f;
  s.camera.aperture_ratio = 1.7f;
  s.settings.dof_dice_factor = 0.75f;
  return s;
}

// Motion: the camera, a mesh's transform and another's points at three
// steps (the middle one the shutter centre's, as the reader takes it), as
// Shutter and MotionBegin blocks; the image is the same.
Scene moving_scene() {
  Scene s = full_scene();
  s.motion_steps = 3;
  s.shutter_curve = {1.0f, 0.75f, 0.125f, 0.0f};
  for (int k = 0; k < 3; ++k) {
    const float t = float(k - 1);
    s.camera.motion_world_to_camera.push_back(glm::translate(glm::mat4(1.0f), glm::vec3(0.05f * t, 0.0f, 0.0f)) *
                                              s.camera.world_to_camera);
  }
  s.camera.world_to_camera = s.camera.motion_world_to_camera[1];
  Mesh& a = s.meshes[0];
  for (int k = 0; k < 3; ++k)
    a.motion_object_to_world.push_back(glm::rotate(glm::mat4(1.0f), 0.1f * float(k - 1), glm::vec3(0, 1, 0)) *
                                       a.object_to_world);
  a.object_to_world = a.motion_object_to_world[1];
  Mesh& b = s.meshes.back();
  for (int k = 0; k < 3; ++k) {
    std::vector<glm::vec3> pts = b.points;
    for (glm::vec3& p : pts) p.y += 0.1f * float(k - 1) * p.x;
    b.motion_points.push_back(pts);
  }
  b.points = b.motion_points[1];
  return s;
}

TEST(RibWriter, MotionRoundTrips) {
  const Scene s = moving_scene();
  ASSERT_GE(s.meshes.size(), 2u);
  expect_same_scene(s, round_trip(s));
}

TEST_F(RibWriterRender, MovingSceneRendersTheSame) {
  Scene s = moving_scene();
  set_samples_per_pixel(s.settings, 4);
  EXPECT_LE(max_difference(s), 1.0f / 255.0f);
}

TEST(RibWriter, DepthOfFieldRoundTrips) {
  const Scene s = defocused_scene();
  const Scene back = round_trip(s);
  expect_same_scene(s, back);
  EXPECT_EQ(back.settings.dof_dice_factor, 0.75f);
}

TEST(RibWriter, SamplerAndSampleMemoryRoundTrip) {
  Scene s = defocused_scene();
  s.settings.sampler = Sampler::Micropolygons;
  s.settings.sample_memory_mib = 96.5f;
  const Scene back = round_trip(s);
  EXPECT_EQ(back.settings.sampler, Sampler::Micropolygons);
  EXPECT_EQ(back.settings.sample_memory_mib, 96.5f);
  s.settings.sampler = Sampler::Tiles;
  EXPECT_EQ(round_trip(s).settings.sampler, Sampler::Tiles);
  s.settings.sampler = Sampler::Bins;
  EXPECT_EQ(round_trip(s).settings.sampler, Sampler::Bins);
  s.settings.resolver = Resolver::Pixels;
  EXPECT_EQ(round_trip(s).settings.resolver, Resolver::Pixels);
  for (const OcclusionWaves w : {OcclusionWaves::On, OcclusionWaves::Off}) {
    s.settings.occlusion_waves = w;
    EXPECT_EQ(round_trip(s).settings.occlusion_waves, w);
  }
  // The defaults are left out of the file.
  EXPECT_EQ(to_rib(defocused_scene()).find("samplememory"), std::string::npos);
}

TEST_F(RibWriterRender, DefocusedSceneRendersTheSame) {
  Scene s = defocused_scene();
  set_samples_per_pixel(s.settings, 4);
  EXPECT_LE(max_difference(s), 1.0f / 255.0f);
}

TEST_F(RibWriterRender, OrthographicSceneRendersTheSame) {
  EXPECT_LE(max_difference(ortho_scene()), 1.0f / 255.0f);
}

}  // namespace
}  // namespace mp::test
