// Swapping a surface's front and back (RenderMan's ReverseOrientation) by
// reordering its data: faces' loops reversed, Bezier nets mirrored in u.
#pragma once

#include <cstddef>

#include "micropoly/scene.h"

namespace mp {

// Reverses the loops of faces [first_face, end) whose first corner is
// `first_index`, with the per-corner data (UVs, corner normals) that belongs
// to them.
void reverse_faces(Mesh& mesh, size_t first_face = 0, size_t first_index = 0);
// Mirrors each patch from `first_patch` on in u, which negates dPdu and so
// the normal: its 4x4 net and its corner UVs.
void mirror_patches_u(BezierPatches& set, size_t first_patch = 0);

}  // namespace mp
