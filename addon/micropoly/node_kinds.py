# SPDX-License-Identifier: GPL-3.0-or-later
"""What node_compiler and the node families it calls (node_registry.py) share:
the OpenCL types of a socket's value, the range a texture's Fac keeps and
literals.
Imports nothing, so every node module can import it and none imports
another's compiler."""

FLOAT, VEC = "float", "float3"
# A texture's Fac stays close to [0, 1]; displacement bounds derived from it
# take this margin on both sides.
FAC_RANGE = (-0.25, 1.25)


def finite(x):
    """x as a float, NaN and infinities as 0 (a program must compile)."""
    x = float(x)
    return 0.0 if x != x or x in (float("inf"), float("-inf")) else x


def literal(x):
    """An OpenCL float literal."""
    return repr(finite(x)) + "f"


def vector_literal(v):
    """An OpenCL float3 literal of v's first three values (0 for missing)."""
    v = list(v)[:3] + [0.0] * max(0, 3 - len(v))
    return f"(float3)({literal(v[0])}, {literal(v[1])}, {literal(v[2])})"
