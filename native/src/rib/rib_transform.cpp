// Transformations, named coordinate systems, orientation, sides and ray
// visibility.
//
// RenderMan transforms row vectors (p' = p M) and concatenates new
// transformations in front of the current one (CTM' = M CTM), so the last
// transformation in the file applies to points first (RI spec 3.2, 4.3).
// In GLM's column-vector convention the matrix is G = M^T and the same
// concatenation is CTM' = CTM * G: the familiar OpenGL order.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "rib/rib_parser.h"

namespace mp::rib {

glm::mat4 Parser::read_matrix(ArgReader& args) {
  // RenderMan writes M row by row with the translation in elements 12..14;
  // read column-major, those 16 floats are exactly G = M^T.
  const std::vector<double> v = args.numbers(16);
  float f[16];
  for (int i = 0; i < 16; ++i) f[i] = static_cast<float>(v[static_cast<size_t>(i)]);
  return glm::make_mat4(f);
}

void Parser::req_identity(ArgReader& args) {
  args.done();
  // Inside the world block the identity is world space; before it, camera space.
  attrs_.ctm = glm::mat4(1.0f);
}

void Parser::req_transform(ArgReader& args) {
  const glm::mat4 m = read_matrix(args);
  args.done();
  attrs_.ctm = m;  // relative to world space inside the world block
}

void Parser::req_concat_transform(ArgReader& args) {
  const glm::mat4 m = read_matrix(args);
  args.done();
  attrs_.ctm = attrs_.ctm * m;
}

void Parser::req_translate(ArgReader& args) {
  const std::vector<double> t = args.numbers(3);
  args.done();
  attrs_.ctm = glm::translate(attrs_.ctm, glm::vec3(t[0], t[1], t[2]));
}

void Parser::req_rotate(ArgReader& args) {
  const double angle = args.number();
  const std::vector<double> axis = args.numbers(3);
  args.done();
  const glm::dvec3 a(axis[0], axis[1], axis[2]);
  const double len = glm::length(a);
  if (!(len > 0.0) || !std::isfinite(len)) args.fail("rotation axis is zero");
  // Same matrix as the right-handed rotation in a right-handed space; in
  // RenderMan's left-handed space it reads as a left-handed rotation.
  const glm::dmat4 r = glm::rotate(glm::dmat4(1.0), glm::radians(angle), a / len);
  attrs_.ctm = attrs_.ctm * glm::mat4(r);
}

void Parser::req_scale(ArgReader& args) {
  const std::vector<double> s = args.numbers(3);
  args.done();
  attrs_.ctm = glm::scale(attrs_.ctm, glm::vec3(s[0], s[1], s[2]));
}

void Parser::req_coordinate_system(ArgReader& args) {
  const std::string name = args.string();
  args.done();
  coord_systems_[name] = CoordSys{in_world_, attrs_.ctm};
}

void Parser::req_coord_sys_transform(ArgReader& args) {
  const std::string name = args.string();
  args.done();
  const int line = args.request().line;
  if (name == "world") {
    if (!in_world_) args.fail("\"world\" is not defined before WorldBegin");
    attrs_.ctm = glm::mat4(1.0f);
  } else if (name == "camera") {
    attrs_.ctm = in_world_ ? camera_inverse(line) : glm::mat4(1.0f);
  } else if (name == "object" || name == "current" || name == "shader") {
    // Already the current coordinate system.
  } else {
    auto it = coord_systems_.find(name);
    if (it == coord_systems_.end()) args.fail("unknown coordinate system \"" + name + "\"");
    const CoordSys& cs = it->second;
    if (cs.in_world == in_world_)
      attrs_.ctm = cs.ctm;
    else if (!cs.in_world)
      attrs_.ctm = camera_inverse(line) * cs.ctm;  // saved relative to the camera
    else
      args.fail("coordinate system \"" + name + "\" belongs to an earlier world block");
  }
}

void Parser::req_orientation(ArgReader& args) {
  const std::string o = args.string();
  args.done();
  // inside_out: the orientation differs from the current coordinate system's
  // handedness, which flips the primitives' normals (RI spec 3.2, 4.2.14).
  if (o == "outside")
    attrs_.inside_out = false;
  else if (o == "inside")
    attrs_.inside_out = true;
  else if (o == "lh")
    attrs_.inside_out = !current_frame_is_left_handed();
  else if (o == "rh")
    attrs_.inside_out = current_frame_is_left_handed();
  else
    args.fail("orientation must be \"outside\", \"inside\", \"lh\" or \"rh\", not \"" + o + "\"");
}

void Parser::req_reverse_orientation(ArgReader& args) {
  args.done();
  attrs_.inside_out = !attrs_.inside_out;
}

void Parser::req_sides(ArgReader& args) {
  const int sides = args.integer(1, 2);
  args.done();
  attrs_.double_sided = sides == 2;
}

void Parser::visibility_attribute(ArgReader& args, const ParamList& params) {
  // RenderMan's ray visibility: "camera" (seen by the camera) and
  // "transmission" (blocks shadow rays, i.e. casts shadows). The other kinds
  // of rays ("diffuse", "specular", "photon", ...) have no counterpart here.
  int camera = attrs_.visible_camera ? 1 : 0;
  params.get_int("camera", 0, 1, &camera);
  int transmission = attrs_.cast_shadows ? 1 : 0;
  params.get_int("transmission", 0, 1, &transmission);
  attrs_.visible_camera = camera != 0;
  attrs_.cast_shadows = transmission != 0;
  for (const Param& p : params.params())
    if (p.name != "camera" && p.name != "transmission")
      warn_once("attribute-visibility:" + p.name, args.request().line,
                "Attribute \"visibility\": parameter \"" + p.name + "\" is ignored");
}

}  // namespace mp::rib
