// Turns fuzz bytes into a Scene as the Python module's Scene/Mesh setters
// could fill it: arrays of any length, any float (NaN, infinities, huge,
// subnormal), any index (negative, out of range), any enum value the
// bindings accept. Sizes are bounded so that one input stays fast.
#pragma once

#include <fuzzer/FuzzedDataProvider.h>

#include "micropoly/scene.h"

namespace mp::fuzz {

Scene decode_scene(FuzzedDataProvider& in);

}  // namespace mp::fuzz
