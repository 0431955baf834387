// IEEE 754 half floats (binary16) widened to floats: the image's half-float
// read-back (pipeline/frame/image_read_back.h) lands through these.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mp {

// One half, exactly (every half is a float), in portable code.
float half_to_float(uint16_t h);
// `n` halves into floats: with the processor's F16C instructions where it
// has them (x86 since 2012), else half_to_float.
void halves_to_floats(const uint16_t* in, float* out, size_t n);
// Whether halves_to_floats uses F16C on this processor (tests).
bool halves_use_f16c();

}  // namespace mp
