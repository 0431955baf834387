# SPDX-License-Identifier: GPL-3.0-or-later
"""What node_compiler and the node families it calls (node_textures) share:
the OpenCL types of a socket's value and the range a texture's Fac keeps.
Imports nothing, so every node module can import it and none imports
another's compiler."""

FLOAT, VEC = "float", "float3"
# A texture's Fac stays close to [0, 1]; displacement bounds derived from it
# take this margin on both sides.
FAC_RANGE = (-0.25, 1.25)
