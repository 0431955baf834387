// Field-by-field comparison of two Scenes, for the RIB round-trip fuzz
// target: read -> write -> read must give back the Scene that was read.
#pragma once

#include <string>

#include "micropoly/scene.h"

namespace mp::fuzz {

// The first difference between `a` (the scene that was written) and `b`
// (what reading the written RIB gave), as "path: a-value vs b-value", or an
// empty string when they agree. Floats must agree exactly, sign of zero and
// NaN payloads aside: the writer prints every float in the shortest decimal
// form that reads back to the same float (std::to_chars, rib_writer.cpp), so
// nothing is lost on the way. Fields that the material model or light type
// does not use, which the writer may leave out, are not compared; the
// writer's documented normalisations are applied to `a` first (see the
// comments in scene_compare.cpp).
std::string first_difference(const Scene& a, const Scene& b);

}  // namespace mp::fuzz
