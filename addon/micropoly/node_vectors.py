# SPDX-License-Identifier: GPL-3.0-or-later
"""Vector nodes: Mapping, Vector Transform, Displacement, Vector
Displacement, Bump and Normal Map. Displacement nodes add their bound (how
far they move the surface) to the compiler's; Bump evaluates its height at
the grid neighbours through a helper function.

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py)."""

import math

from .node_kinds import FLOAT, VEC

MAPPING_TYPES = ["POINT", "TEXTURE", "VECTOR", "NORMAL"]


def displacement_node_bound(value, mid, scale, spread):
    """How far a displacement node moves the surface, from its inputs' value
    ranges (value: a height, or each component of a vector, `spread` sqrt(3)
    for the vector's length), or None when they are unknown."""
    (_, _, vr), (_, _, mr), (_, _, sr) = value, mid, scale
    if vr and mr and sr and mr[0] == mr[1] and sr[0] == sr[1]:
        return abs(sr[0]) * spread * max(abs(vr[1] - mr[0]), abs(vr[0] - mr[0]))
    return None


def emit_mapping(c, node):
    v = c.input(node, "Vector", VEC)[0]
    loc = c.input(node, "Location", VEC)[0] if "Location" in node.inputs else "(float3)(0.0f)"
    rot = c.input(node, "Rotation", VEC)[0] if "Rotation" in node.inputs else "(float3)(0.0f)"
    scl = c.input(node, "Scale", VEC)[0] if "Scale" in node.inputs else "(float3)(1.0f)"
    return {"Vector": c.fn.temp(VEC, f"mp_mapping({MAPPING_TYPES.index(node.vector_type)}, {v}, {loc}, "
                                     f"{rot}, {scl})")}


def emit_vector_transform(c, node):
    spaces = ("WORLD", "OBJECT", "CAMERA")
    v = c.input(node, "Vector", VEC)[0]
    kind = ("POINT", "VECTOR", "NORMAL").index(node.vector_type)
    return {"Vector": c.fn.temp(VEC, f"mp_vector_transform(g, {kind}, {spaces.index(node.convert_from)}, "
                                     f"{spaces.index(node.convert_to)}, {v}, "
                                     f"{1 if c.version < 400 else 0})")}


def emit_displacement(c, node):
    if node.inputs["Normal"].is_linked:
        c.warn(node, "a linked Normal input is not supported; the surface normal is used")
    h, mid, scale = (c.input(node, k, FLOAT) for k in ("Height", "Midlevel", "Scale"))
    c.displacement_bounds.append(displacement_node_bound(h, mid, scale, 1.0))
    amount = f"(({h[0]}) - ({mid[0]})) * ({scale[0]})"
    if getattr(node, "space", "OBJECT") == "WORLD":
        # World units along the world-space normal: the bound is in world units too.
        c.displacement_world = True
        return {"Displacement": c.fn.temp(VEC, f"mp_displacement_world(g, {amount})")}
    return {"Displacement": c.fn.temp(VEC, f"{amount} * g->N")}


def emit_vector_displacement(c, node):
    """Vector Displacement: (Vector - Midlevel) x Scale in tangent space
    (x along the active UV map's tangent, y along the normal, z along
    the bitangent, as Cycles reads it), object space or world space."""
    vec = c.input(node, "Vector", VEC)
    mid, scale = c.input(node, "Midlevel", FLOAT), c.input(node, "Scale", FLOAT)
    c.displacement_bounds.append(displacement_node_bound(vec, mid, scale, math.sqrt(3.0)))
    d = f"((({vec[0]}) - (float3)({mid[0]})) * ({scale[0]}))"
    if node.space == "TANGENT":
        ta, tb = c.resources.tangent_layers("")
        if ta < 0:
            c.warn(node, "the UV layers ran out, so it has no tangents; only the normal component "
                            "displaces")
        expr = f"mp_vector_displacement_tangent(g, {ta}, {tb}, {d})"
    elif node.space == "WORLD":
        c.displacement_world = True
        expr = f"mp_world_dir_to_object(g, {d})"
    else:
        expr = d
    return {"Displacement": c.fn.temp(VEC, expr)}


def emit_bump(c, node):
    """Bump: heights at this vertex and its grid neighbours (mp_bump)."""
    c.uses_neighbours = True
    strength = c.input(node, "Strength", FLOAT)[0]
    distance = c.input(node, "Distance", FLOAT)[0]
    n_in = c.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
    if not node.inputs["Height"].is_linked:
        return {"Normal": (n_in, VEC, None)}
    h = c.height_function(node, "Height")
    invert = 1 if node.invert else 0
    return {"Normal": c.fn.temp(VEC, f"mp_bump(g, {h}(g), g->dx ? {h}(g->dx) : 0.0f, "
                                        f"g->dy ? {h}(g->dy) : 0.0f, {strength}, {distance}, {invert}, {n_in})")}


def emit_normal_map(c, node):
    """Normal Map: tangent space from the UV map's tangents (mp_normal_map_tangent),
    or object space."""
    strength = c.input(node, "Strength", FLOAT)[0]
    color = c.input(node, "Color", VEC)[0]
    if node.space == "TANGENT":
        c.uses_neighbours = True  # the tangent from UV differences, where there are none
        uv = c.resources.uv_layer(node.uv_map)
        ta, tb = c.resources.tangent_layers(node.uv_map)
        # Blender 4.0 scales the map's tilt by Strength instead of blending normals.
        v4 = 1 if c.version >= 400 else 0
        expr = f"mp_normal_map_tangent(g, {uv}, {ta}, {tb}, {strength}, {color}, {v4})"
    else:
        blender = 1 if node.space.startswith("BLENDER") else 0
        world = 1 if node.space in ("WORLD", "BLENDER_WORLD") else 0
        expr = f"mp_normal_map_object(g, {blender}, {world}, {strength}, {color})"
    return {"Normal": c.fn.temp(VEC, expr)}


NODES = {
    "MAPPING": emit_mapping,
    "VECT_TRANSFORM": emit_vector_transform,
    "DISPLACEMENT": emit_displacement,
    "VECTOR_DISPLACEMENT": emit_vector_displacement,
    "BUMP": emit_bump,
    "NORMAL_MAP": emit_normal_map,
}
