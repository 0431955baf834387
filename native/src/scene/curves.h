// Curves (Blender's Curves objects, the hair of 3.3 and later) as round
// tubes of bicubic Bezier patches, which the pipeline bounds, splits, dices,
// shades and shadows as any patch.
//
// A curve's points are Catmull-Rom keys, as Cycles reads hair: segment i runs
// from key i to key i+1 with tangents from its neighbours (the end keys
// doubled), and the radius follows the same basis. Each segment becomes 4
// patches, one per quarter turn about the centre line: u goes around (a cubic
// arc per quarter, scene/quadrics.h's construction), v along the segment.
// The cross-section at each key is an exact circle (within the arcs' 2.7e-4
// of the radius) perpendicular to the key's tangent, in a frame carried from
// key to key by parallel transport, so the tube does not twist and the two
// segments at a key share that ring bit for bit (crack-free dicing).
// Between keys the sections blend the two keys' frames. Both sides are
// front (the tubes are open at the ends: a hair's tip is a disc-less end).
// This is the shape Cycles calls 3D Curves; its Rounded Ribbons draw the
// same width (a ribbon facing each ray) with normals as round as these.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "micropoly/scene.h"

namespace mp {

struct CurveSet {
  std::string name;
  std::vector<glm::vec3> points;  // object space, all curves' keys in order
  std::vector<float> radii;       // one per point
  std::vector<int> offsets;       // curves + 1: curve c has points [offsets[c], offsets[c + 1])
  // What material programs read as UV layer k (BezierPatches::uv_layers): one
  // value per point, linear along each segment in its parameter, as Cycles
  // interpolates curve-key attributes (a curve's own values repeat on its
  // points). The add-on puts UV maps, attributes and Hair Info here.
  std::vector<std::vector<glm::vec2>> point_layers;
  glm::mat4 object_to_world{1.0f};
  int material = 0;
  ObjectInfo info;
  bool visible_camera = true;
  bool cast_shadows = true;
  // Ribbons facing each view (Cycles' Rounded Ribbons, RenderMan's Curves;
  // one MP_PATCH_CURVE patch a segment) instead of round tubes (Cycles' 3D
  // Curves, kTubePatchesPerSegment patches a segment).
  bool ribbons = false;
  // Motion blur (Scene::motion_steps): the points and the transform at each
  // motion step, or empty where they do not move (as Mesh). Each step's
  // tubes are cut as the shutter centre's are, so the patches match.
  std::vector<std::vector<glm::vec3>> motion_points;
  std::vector<glm::mat4> motion_object_to_world;
};

constexpr int kTubePatchesPerSegment = 4;

// One cubic Bezier segment of a curve: its centre line and its radius.
struct CurveSegment {
  glm::dvec3 p[4];
  double r[4];
};

// Catmull-Rom keys (at least 2) and their radii as Bezier segments, the end
// keys doubled (Cycles' hair curves).
void catmull_rom_segments(const std::vector<glm::dvec3>& keys, const std::vector<double>& radii,
                          std::vector<CurveSegment>& segments);
// One segment as a ribbon's 16 points (BezierPatches::ribbons), appended
// to `out`.
void add_ribbon(const CurveSegment& segment, std::vector<glm::vec3>& out);
// The tube around consecutive segments (each starting where the last ended)
// as Bezier nets, kTubePatchesPerSegment per segment, appended to `out`.
void add_tube(const std::vector<CurveSegment>& segments, std::vector<glm::vec3>& out);

// Curves already in Bezier form (RIB's Curves through their basis) as one
// BezierPatches set of tubes, or ribbons where meta.ribbons says: each run is a chain of segments, each starting
// where the last ended. The object's fields come from `meta` (its points,
// radii and offsets are not read). Nothing is added for no segments.
void add_bezier_curves(Scene& scene, const CurveSet& meta, const std::vector<std::vector<CurveSegment>>& runs);

// Appends the curves' tubes (or ribbons) as one BezierPatches set (none where no curve
// has a segment). Curves of fewer than 2 points, or with a point or radius
// that is not finite or a radius below 0, are skipped; returns how many
// were. Throws mp::Error for offsets that do not describe the points.
size_t add_curves(Scene& scene, const CurveSet& curves);

}  // namespace mp
