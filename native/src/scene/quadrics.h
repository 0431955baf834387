// RenderMan's quadrics (RI spec 3.2, section 5.4: Sphere, Cylinder, Cone,
// Disk, Paraboloid, Hyperboloid, Torus) as bicubic Bezier nets, which the
// pipeline bounds, splits and dices as any Patch: the RIB reader's quadrics,
// and the unit sphere and disc that point clouds instance (points.h).
//
// Every quadric is a surface of revolution about z: a profile curve (a
// circular arc, a line or a parabola, in the xz-plane, or a line in space
// for the hyperboloid) swept by theta from 0 to thetamax. The profile is cut
// into cubic Bezier segments (exact for lines and the parabola; arcs of at
// most kMaxArcDegrees each take the usual tangent-length construction,
// k = 4/3 tan(angle / 4)), and the sweep into spans of at most
// kMaxArcDegrees, each a cubic arc of the same construction. Rotating a point
// about z is linear in the point, so the tensor product of the two is the
// profile swept by the approximate arc exactly: P(u, v) = R~(u) c(v).
// The radial error of a cubic arc of angle a is about 2.7e-4 (a / 90 deg)^6
// of its radius: at most 4.3e-6 for the 45 degree spans used here.
//
// Orientation: u follows theta and v the profile from its RI start to its
// end, so dPdu x dPdv is RenderMan's geometric normal (outward for positive
// radii and thetamax, +z for a Disk); the reader's orientation rules then
// apply as to any Patch. Seams (theta = 0 and 360, the profile's segment
// ends) are built from the same numbers on both sides, so neighbouring nets
// share bit-identical edges (the pipeline's crack-free dicing); poles collapse
// to one point.
//
// Parametrisation: RI's u and v, except along a Paraboloid's profile, whose
// parameter is the radius (exact parabola) rather than z. Patches carry no
// texture coordinates of the quadric as a whole.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mp {

enum class QuadricKind { Sphere, Cylinder, Cone, Disk, Paraboloid, Hyperboloid, Torus };

constexpr double kMaxArcDegrees = 45.0;

// The cubic Bezier arc on the unit circle from `from` to `to` degrees (at
// most 90 apart): its 4 control points, the ends exact at multiples of 90
// degrees and the same for angles a whole turn apart.
std::array<glm::dvec2, 4> unit_arc(double from, double to);

// The request name's kind; false for other names.
bool quadric_kind(const std::string& request, QuadricKind* kind);
// How many numbers the request takes (Hyperboloid: two points and thetamax).
size_t quadric_arg_count(QuadricKind kind);

// The quadric's Bezier nets, 16 points each (u along each row, as Patch),
// from its request's numbers in RI order, arcs cut into pieces of at most
// `max_arc` degrees (90: a radial error of 2.7e-4 of the radius per arc).
// Empty where the surface has no area (a zero radius, height or sweep);
// throws mp::Error with a reason for numbers that describe no surface (a
// Paraboloid whose z range crosses 0).
std::vector<glm::vec3> quadric_patches(QuadricKind kind, const std::vector<double>& args,
                                       double max_arc = kMaxArcDegrees);

}  // namespace mp
