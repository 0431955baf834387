# SPDX-License-Identifier: GPL-3.0-or-later
"""Input nodes: where a shading point is and what it sees (Texture
Coordinate, UV Map, Geometry, Tangent, Fresnel, Layer Weight, Attribute,
Hair Info, Point Info, Light Path, Object Info) and constants (Value, RGB).

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py)."""

from .node_kinds import FLOAT, VEC, literal


def emit_texture_coordinate(c, node):
    fn = c.fn
    if c.world:
        for name in ("Camera", "Window"):
            if node.outputs[name].is_linked:
                c.warn(node, f"the {name} output gives zero in the world's light (baked once for "
                             "every view); the background behind objects has it")
    obj_coords = "g->P"
    other = getattr(node, "object", None)
    if other is not None and node.outputs["Object"].is_linked:
        # That object's placement is among the material's node
        # values: moving it re-uploads them and builds nothing.
        m = other.matrix_world.inverted()
        rows = ", ".join(c.param4([m[r][col] for col in range(4)]) for r in range(3))
        obj_coords = fn.temp(VEC, f"mp_point_in_space(g, {rows})")[0]
    # Normal is object space, Reflection (the view mirrored about
    # the normal) world space, Camera Cycles' +Z-forward camera space.
    reflection = "(2.0f * dot(g->Nw, g->I) * g->Nw - g->I)"
    outs = {"Generated": ("g->generated", VEC, None), "Object": (obj_coords, VEC, None),
            "Normal": ("g->N", VEC, None), "Camera": ("g->camera", VEC, None),
            "Window": ("g->window", VEC, None), "Reflection": (reflection, VEC, None)}
    if node.outputs["UV"].is_linked:
        outs["UV"] = (c.uv(), VEC, None)
    return outs


def emit_uv_map(c, node):
    if getattr(node, "from_instancer", False):
        c.warn(node, "From Instancer is not supported; the object's own UV map is used")
    return {"UV": (c.uv(node.uv_map), VEC, None)}


def emit_geometry(c, node):
    """Geometry node, in world space as Cycles': True Normal is the
    limit surface's normal (the smooth one; Micropoly's surfaces have
    no facets), Tangent the radial one about the object's Z axis."""
    for name in ("Parametric", "Pointiness", "Random Per Island"):
        if name in node.outputs and node.outputs[name].is_linked:
            c.warn(node, f"the {name} output is not supported; it gives its default")
    backfacing = c.fn.temp(FLOAT, "(float)mp_backfacing(g)", (0.0, 1.0))
    tangent = c.fn.temp(VEC, "mp_world_tangent(g, mp_radial_tangent(g))")
    return {"Position": ("mp_world_position(g)", VEC, None), "Normal": ("g->Nw", VEC, None),
            "True Normal": ("g->Nw", VEC, None), "Incoming": ("g->I", VEC, None),
            "Tangent": tangent, "Backfacing": backfacing}


def emit_tangent(c, node):
    """Tangent node: radial about an object axis through Generated
    coordinates, or a UV map's MikkTSpace tangent (zero without one, as
    Cycles gives), in world space and orthogonal to the normal."""
    if node.direction_type == "UV_MAP":
        ta, tb = c.resources.tangent_layers(node.uv_map)
        t = f"mp_uv_tangent(g, {ta}, {tb}, 0)"
    else:
        t = f"mp_radial_tangent_axis(g, {'XYZ'.index(node.axis)})"
    return {"Tangent": c.fn.temp(VEC, f"mp_world_tangent(g, {t})")}


def emit_fresnel(c, node):
    n = c.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
    return {"Fac": c.fn.temp(FLOAT, f"mp_fresnel_node(g, {c.input(node, 'IOR', FLOAT)[0]}, {n})", (0.0, 1.0))}


def emit_layer_weight(c, node):
    n = c.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
    facing = c.fn.temp(FLOAT, "0.0f", (0.0, 1.0))
    fresnel = c.fn.temp(FLOAT, f"mp_layer_weight(g, {c.input(node, 'Blend', FLOAT)[0]}, {n}, &{facing[0]})",
                        (0.0, 1.0))
    return {"Fresnel": fresnel, "Facing": facing}


def emit_attribute(c, node):
    """Attribute (Geometry type) and Color Attribute: a mesh's or curve's
    attribute, interpolated over the surface as UVs are (two layers: RG and
    BA), plus a point cloud's, one value per point (a slot each point
    carries: meshes and curves read zero there, points zero in the layers);
    Attribute of type Object or Instancer: the object's or instance's value
    (export_attributes.py)."""
    kind = getattr(node, "attribute_type", "GEOMETRY") if node.type == "ATTRIBUTE" else "GEOMETRY"
    if kind in ("OBJECT", "INSTANCER"):
        # One value per object or instance (export_attributes.py).
        slot = c.resources.object_attribute(node.attribute_name, kind)
        if slot < 0:
            return {}
        rgba = c.fn.temp("float4", f"mp_object_attribute(g, {slot}u)")[0]
    elif kind != "GEOMETRY":
        c.warn(node, f"{kind.replace('_', ' ').title()} attributes are not supported; it gives zero")
        return {}
    else:
        name = node.layer_name if node.type == "VERTEX_COLOR" else node.attribute_name
        ka, kb = c.resources.attribute_layers(name)
        slot = c.resources.object_attribute(name, "POINT")
        parts = []
        if ka >= 0:
            parts.append(f"(float4)(g->uv[{ka}].x, g->uv[{ka}].y, g->uv[{kb}].x, g->uv[{kb}].y)")
        if slot >= 0:
            parts.append(f"mp_object_attribute(g, {slot}u)")
        if not parts:
            return {}
        rgba = c.fn.temp("float4", " + ".join(parts))[0]
    color = (f"{rgba}.xyz", VEC, None)
    # Fac: a float attribute's value, a colour's or vector's average (Cycles).
    return {"Color": color, "Vector": color, "Fac": (f"dot({rgba}.xyz, (float3)(1.0f / 3.0f))", FLOAT, None),
            "Alpha": (f"{rgba}.w", FLOAT, None)}


def emit_hair_info(c, node):
    """Hair Info (Curves Info in 4.x): a curve's intercept (its arc length
    to the point over its length, linear between keys), length, random
    (Cycles' hash of the curve's number) and thickness (its diameter),
    carried per point in two attribute layers (export_curves.py); Tangent
    Normal from the fibre's direction. Zero on meshes, as in Cycles."""
    ka, kb = c.resources.hair_info_layers()
    zero = ("0.0f", FLOAT, (0.0, 0.0))
    if ka < 0:
        outs = {"Is Strand": zero, "Intercept": zero, "Length": zero, "Thickness": zero, "Random": zero,
                "Tangent Normal": ("(float3)(0.0f)", VEC, None)}
    else:
        # Every curve has a length; meshes read zero.
        strand = c.fn.temp(FLOAT, f"(g->uv[{ka}].y > 0.0f ? 1.0f : 0.0f)", (0.0, 1.0))
        outs = {"Is Strand": strand, "Intercept": (f"g->uv[{ka}].x", FLOAT, (0.0, 1.0)),
                "Length": (f"g->uv[{ka}].y", FLOAT, None), "Random": (f"g->uv[{kb}].x", FLOAT, (0.0, 1.0)),
                "Thickness": (f"g->uv[{kb}].y", FLOAT, None)}
        if node.outputs["Tangent Normal"].is_linked:
            c.uses_hair = True  # the fibre's direction (material_program.cl)
            outs["Tangent Normal"] = c.fn.temp(VEC, f"{strand[0]} * mp_hair_tangent_normal(g)")
    return {node.outputs[name].identifier: value for name, value in outs.items() if name in node.outputs}


def emit_point_info(c, node):
    """Point Info: a point's centre (world space), radius and random
    number (Cycles' hash of its number), from the slot each point of a
    cloud carries (export_points.py: random, radius, 1 on points); zero
    elsewhere, as in Cycles."""
    slot = c.resources.object_attribute("micropoly:point info", "POINT_INFO")
    if slot < 0:
        outs = {"Position": ("(float3)(0.0f)", VEC, None), "Radius": ("0.0f", FLOAT, (0.0, 0.0)),
                "Random": ("0.0f", FLOAT, (0.0, 0.0))}
    else:
        info = c.fn.temp("float4", f"mp_object_attribute(g, {slot}u)")[0]
        centre = ("(g->object ? (float3)(g->object->to_world[3], g->object->to_world[7], "
                  "g->object->to_world[11]) : (float3)(0.0f))")
        outs = {"Position": c.fn.temp(VEC, f"{info}.z * {centre}"), "Radius": (f"{info}.y", FLOAT, None),
                "Random": (f"{info}.x", FLOAT, (0.0, 1.0))}
    return {node.outputs[name].identifier: value for name, value in outs.items() if name in node.outputs}


def emit_light_path(c, node):
    """Light Path: what a camera ray shading direct light sees (every
    depth 0, no scattering), a shadow map's ray where Micropoly
    evaluates transparency for shadows, or in a world the camera's view
    of it (Is Camera Ray 1) or the light it sends to surfaces (all 0, as
    Cycles evaluates its background light)."""
    outs = {o.identifier: ("0.0f", FLOAT, (0.0, 0.0)) for o in node.outputs}
    outs["Is Camera Ray"] = ("(g->camera_ray ? 1.0f : 0.0f)", FLOAT, (0.0, 1.0))
    outs["Is Shadow Ray"] = ("(g->shadow_ray ? 1.0f : 0.0f)", FLOAT, (0.0, 1.0))
    outs["Ray Length"] = ("g->ray_length", FLOAT, None)
    return outs


def emit_object_info(c, node):
    """Per object (DeviceObject: its colour, pass index and random number,
    export_mesh.py); the material's pass index is a constant."""
    index = float(getattr(c.material, "pass_index", 0))
    outs = {"Location": ("(g->object ? (float3)(g->object->to_world[3], g->object->to_world[7], "
                         "g->object->to_world[11]) : (float3)(0.0f))", VEC, None),
            "Color": ("(g->object ? (float3)(g->object->color[0], g->object->color[1], g->object->color[2])"
                      " : (float3)(1.0f))", VEC, None),
            "Alpha": ("(g->object ? g->object->color[3] : 1.0f)", FLOAT, None),
            "Object Index": ("(g->object ? g->object->info[0] : 0.0f)", FLOAT, None),
            "Random": ("(g->object ? g->object->info[1] : 0.0f)", FLOAT, None),
            "Material Index": (literal(index), FLOAT, (index, index))}
    return {node.outputs[name].identifier: value for name, value in outs.items() if name in node.outputs}


def emit_value(c, node):
    x = float(node.outputs[0].default_value)
    return {node.outputs[0].identifier: (c.param(x), FLOAT, (x, x))}


def emit_rgb(c, node):
    return {node.outputs[0].identifier: (c.param3(node.outputs[0].default_value), VEC, None)}


NODES = {
    "TEX_COORD": emit_texture_coordinate,
    "UVMAP": emit_uv_map,
    "NEW_GEOMETRY": emit_geometry,
    "TANGENT": emit_tangent,
    "FRESNEL": emit_fresnel,
    "LAYER_WEIGHT": emit_layer_weight,
    "ATTRIBUTE": emit_attribute,
    "VERTEX_COLOR": emit_attribute,
    "HAIR_INFO": emit_hair_info,
    "POINT_INFO": emit_point_info,
    "LIGHT_PATH": emit_light_path,
    "OBJECT_INFO": emit_object_info,
    "VALUE": emit_value,
    "RGB": emit_rgb,
}
