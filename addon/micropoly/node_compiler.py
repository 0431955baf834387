# SPDX-License-Identifier: GPL-3.0-or-later
"""Material node trees -> OpenCL C material programs.

A material's Surface shader inputs (Principled BSDF, Diffuse BSDF, Emission)
and its Displacement output are translated into two device functions,
mp_node_surface and mp_node_displacement (the contract is in
kernels/materials/material_program.cl; the node functions they call are in
kernels/materials/mp_node_lib.h and kernels/textures/). Every output socket
that is used becomes one local variable, computed once. An unsupported node
gives one warning naming the material and the node, and its outputs take
their default values, so a render never fails on a node it cannot run."""

import math

import bpy

from . import node_textures
from .node_kinds import FAC_RANGE, FLOAT, VEC

# Closures a shading point holds (MP_MAX_CLOSURES, kernels/closures/mp_closures.h).
MAX_CLOSURES = 10

MATH_OPS = ["ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT", "INVERSE_SQRT",
            "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN", "SIGN", "COMPARE",
            "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO",
            "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE", "ARCTANGENT",
            "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS", "DEGREES"]
VMATH_OPS = ["ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT", "PROJECT", "REFLECT",
             "DOT_PRODUCT", "DISTANCE", "LENGTH", "SCALE", "NORMALIZE", "ABSOLUTE", "MINIMUM", "MAXIMUM", "FLOOR",
             "CEIL", "FRACTION", "MODULO", "WRAP", "SNAP", "SINE", "COSINE", "TANGENT", "FACEFORWARD"]
VMATH_VALUE_OPS = {"DOT_PRODUCT", "DISTANCE", "LENGTH"}
BLEND_MODES = ["MIX", "ADD", "MULTIPLY", "SUBTRACT", "SCREEN", "DIVIDE", "DIFFERENCE", "DARKEN", "LIGHTEN",
               "OVERLAY", "DODGE", "BURN", "SOFT_LIGHT", "LINEAR_LIGHT", "EXCLUSION", "HUE", "SATURATION", "VALUE",
               "COLOR"]
RANGE_MODES = ["LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP"]
MAPPING_TYPES = ["POINT", "TEXTURE", "VECTOR", "NORMAL"]
FRACTAL_TYPES = ["FBM", "MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "HETERO_TERRAIN"]
VORONOI_FEATURES = ["F1", "F2", "SMOOTH_F1", "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS"]
VORONOI_METRICS = ["EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI"]
TEXTURE_HEADERS = {"TEX_NOISE": "mp_tex_noise.h", "TEX_MUSGRAVE": "mp_tex_noise.h",
                   "TEX_VORONOI": "mp_tex_voronoi.h", "TEX_WAVE": "mp_tex_wave.h"}
IMAGE_INTERPOLATION = {"Linear": 0, "Closest": 1, "Cubic": 2, "Smart": 2}  # Cycles renders Smart as Cubic
IMAGE_EXTENSION = {"REPEAT": 0, "EXTEND": 1, "CLIP": 2, "MIRROR": 3}
# Sky Texture models with a precomputed texture (native nishita_sky_texture).
SKY_MODELS = ("NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING")
# A world is baked by sampling its map's texel centres (512 texels around by
# default); the sun's disc, smaller than a texel, has its light spread over
# 2.5 texels of that map so every bake holds it to within 1%
# (kernels/textures/mp_tex_sky.h).
WORLD_SUN_SPREAD = 2.5 * 2.0 * math.pi / 512


def blender_version():
    major, minor = bpy.app.version[:2]
    return major * 100 + minor


def _finite(x):
    x = float(x)
    return 0.0 if x != x or x in (float("inf"), float("-inf")) else x


def _lit(x):
    return repr(_finite(x)) + "f"


def _vec_lit(v):
    v = list(v)[:3] + [0.0] * max(0, 3 - len(v))
    return f"(float3)({_lit(v[0])}, {_lit(v[1])}, {_lit(v[2])})"


def _socket_kind(socket):
    return FLOAT if socket.type in ("VALUE", "INT", "BOOLEAN") else VEC


def _dims(s):
    return int(s[0]) if s and s[0] in "1234" else 3


class CompiledMaterial:
    def __init__(self, source, displaces, shades, displacement_bound, displacement_world=False, alpha=False,
                 params=()):
        self.source = source
        # The node values the program reads (MP_PARAM in its source): trees
        # that differ only in values share one source, so one program.
        self.params = list(params)
        self.displaces = displaces
        self.shades = shades
        self.alpha = alpha  # the program computes the surface's alpha (which shadow views read too)
        self.displacement_bound = displacement_bound
        self.displacement_world = displacement_world  # the bound is in world units


class _Function:
    """One generated function body: statements and memoised socket values."""

    def __init__(self):
        self.lines = []
        self.values = {}  # (node name, output identifier) -> (expr, kind, range or None)
        self.counter = 0

    def temp(self, kind, expr, value_range=None):
        name = f"v{self.counter}"
        self.counter += 1
        self.lines.append(f"  {kind} {name} = {expr};")
        return name, kind, value_range


class NoResources:
    """What a node tree may ask of the exporter: UV layer and image indices.
    Without an exporter (tests of the compiler alone) UVs read layer 0 and
    images are missing."""

    def uv_layer(self, name):
        return 0

    def tangent_layers(self, name):
        return -1, -1

    def attribute_layers(self, name):
        return -1, -1

    def image(self, image, warn):
        return -1, None

    def array_image(self, key, pixels):
        """Index of an in-memory float RGBA image (`pixels`: the array or a
        function making it), or -1."""
        return -1


class NodeCompiler:
    def __init__(self, material, warnings, user_bound=0.0, resources=None):
        self.material = material
        self.warnings = warnings
        self.user_bound = user_bound
        self.resources = resources or NoResources()
        self.version = blender_version()
        self.headers = set()
        self.warned = set()
        self.fn = None
        self.helpers = []          # extra functions (Bump heights), emitted before the main two
        self.uses_neighbours = False
        self.uses_thin_film = False
        self.uses_subsurface_walk = False
        self.displacement_world = False
        self.displacement_bounds = []
        self.groups = []           # the Group nodes whose trees are being compiled, outermost first
        self.world = False         # compiling a world (baked into a map) rather than a material
        self.transparent = False   # the surface has Transparent closures (its alpha can be below 1)
        self.closures = 0          # closures the surface adds at most (MP_MAX_CLOSURES per vertex)
        self.params = []           # node values the program reads (MP_PARAM); not compiled in

    # ---- node values ----------------------------------------------------------
    # An artist's numbers (socket values, Value and RGB nodes, ramp stops, an
    # object's placement) are read from the material's parameters rather than
    # written into the source: a dragged slider or an animated value then
    # re-uploads numbers and rebuilds no program.
    def param(self, x):
        self.params.append(_finite(x))
        return f"MP_PARAM({len(self.params) - 1})"

    def _params(self, v, n):
        """n values from v (padded with 0) as MP_PARAMn."""
        self.params.extend(_finite(c) for c in (list(v) + [0.0] * n)[:n])
        return f"MP_PARAM{n}({len(self.params) - n})"

    def param3(self, v):
        return self._params(v, 3)

    def param4(self, v):
        return self._params(v, 4)

    def param_table(self, values):
        """A table of values (a curve's samples) as a pointer to the first."""
        self.params.extend(_finite(c) for c in values)
        return f"MP_PARAM_TABLE({len(self.params) - len(values)}, {len(values)})"

    # ---- helpers ----------------------------------------------------------
    def warn(self, node, what):
        where = "".join(f"group '{g.name}' > " for g in self.groups)
        key = (where, node.name, what)
        if key not in self.warned:
            self.warned.add(key)
            owner = "world" if self.world else "material"
            self.warnings.append(f"{owner} '{self.material.name}': {where}node '{node.name}' ({node.bl_label}): "
                                 f"{what}")

    def key(self, node, identifier):
        """Memo key of a node output: node names repeat across group trees."""
        return tuple(g.name for g in self.groups) + (node.name, identifier)

    @staticmethod
    def convert(value, kind, from_type):
        expr, have, rng = value
        if have == kind:
            return value
        if kind == VEC:
            return f"(float3)({expr})", VEC, None
        # Blender turns a color into a float by its luminance and a vector
        # into the average of its components.
        # Both are weighted averages, so a range of the components carries over.
        if from_type == "RGBA":
            return f"mp_rgb_to_bw({expr})", FLOAT, rng
        return f"dot({expr}, (float3)(1.0f / 3.0f))", FLOAT, rng

    def input(self, node, key, kind=None):
        socket = node.inputs[key] if isinstance(key, int) else (node.inputs.get(key) if hasattr(node.inputs, "get")
                                                                 else None)
        if socket is None:
            raise KeyError(key)
        kind = kind or _socket_kind(socket)
        link = next((l for l in socket.links if getattr(l, "is_valid", True) and not getattr(l, "is_muted", False)),
                    None)
        if link is not None:
            from_node, from_socket = link.from_node, link.from_socket
            while from_node.type == "REROUTE":
                inner = from_node.inputs[0].links
                if not inner:
                    from_node = None
                    break
                from_node, from_socket = inner[0].from_node, inner[0].from_socket
            if from_node is not None and from_node.type == "GROUP_INPUT":
                return self.group_input(from_socket, kind)
            if from_node is not None:
                return self.convert(self.output(from_node, from_socket), kind, from_socket.type)
        if not hasattr(socket, "default_value"):
            return ("0.0f", FLOAT, (0.0, 0.0)) if kind == FLOAT else ("(float3)(0.0f)", VEC, None)
        v = socket.default_value
        try:
            seq = list(v)
        except TypeError:
            seq = None
        if kind == FLOAT:
            x = float(seq[0]) if seq is not None else float(v)
            return self.param(x), FLOAT, (x, x)
        return self.param3(seq if seq is not None else [float(v)] * 3), VEC, None

    def output(self, node, socket):
        key = self.key(node, socket.identifier)
        if key not in self.fn.values:
            if getattr(node, "mute", False):
                self.warn(node, "is muted; its outputs take their default values")
                outs = {}
            else:
                outs = self.emit(node)
            for out in node.outputs:
                k = self.key(node, out.identifier)
                if out.identifier in outs:
                    self.fn.values[k] = outs[out.identifier]
                else:
                    dv = getattr(out, "default_value", 0.0)
                    try:
                        seq = list(dv)
                        self.fn.values[k] = (_vec_lit(seq), VEC, None)
                    except TypeError:
                        self.fn.values[k] = (_lit(dv), FLOAT, (float(dv), float(dv)))
        return self.fn.values.get(key, ("0.0f", FLOAT, (0.0, 0.0)))

    def group_input(self, socket, kind):
        """A Group Input socket inside a group: the Group node's input of the
        same identifier, evaluated in the tree around the Group node."""
        if not self.groups:
            return ("0.0f", FLOAT, (0.0, 0.0)) if kind == FLOAT else ("(float3)(0.0f)", VEC, None)
        group = self.groups.pop()
        try:
            index = next((i for i, s in enumerate(group.inputs) if s.identifier == socket.identifier), None)
            if index is None:
                return ("0.0f", FLOAT, (0.0, 0.0)) if kind == FLOAT else ("(float3)(0.0f)", VEC, None)
            return self.input(group, index, kind)
        finally:
            self.groups.append(group)

    def emit_group(self, node):
        """A node group: its Group Output's inputs, compiled inside the group's
        tree (names there are scoped by the Group node)."""
        tree = node.node_tree
        outputs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"] if tree is not None else []
        active = [n for n in outputs if getattr(n, "is_active_output", False)] or outputs
        if not active:
            self.warn(node, "has no node tree or no Group Output; its outputs take their default values")
            return {}
        out_node = active[0]
        result = {}
        self.groups.append(node)
        try:
            for out in node.outputs:
                if out.type == "SHADER" or not out.is_linked:
                    continue
                index = next((i for i, s in enumerate(out_node.inputs) if s.identifier == out.identifier), None)
                if index is not None:
                    result[out.identifier] = self.input(out_node, index, _socket_kind(out))
        finally:
            self.groups.pop()
        return result

    def vector_or_generated(self, node, key="Vector"):
        socket = node.inputs.get(key)
        if socket is not None and socket.is_linked:
            return self.input(node, key, VEC)[0]
        return "g->generated"  # textures default to Generated coordinates

    def uv(self, name=""):
        """The UV layer of that name ("": the mesh's active render UV map)."""
        return f"g->uv[{self.resources.uv_layer(name)}]"

    def by_id(self, node, identifier, kind):
        for i, s in enumerate(node.inputs):
            if s.identifier == identifier:
                return self.input(node, i, kind)
        raise KeyError(identifier)

    # ---- nodes ----------------------------------------------------------------
    def emit(self, node):
        t = node.type
        fn = self.fn
        if t == "TEX_COORD":
            if self.world:
                for name in ("Camera", "Window"):
                    if node.outputs[name].is_linked:
                        self.warn(node, f"the {name} output gives zero in the world's light (baked once for "
                                        "every view); the background behind objects has it")
            obj_coords = "g->P"
            other = getattr(node, "object", None)
            if other is not None and node.outputs["Object"].is_linked:
                # That object's placement is among the material's node
                # values: moving it re-uploads them and builds nothing.
                m = other.matrix_world.inverted()
                rows = ", ".join(self.param4([m[r][c] for c in range(4)]) for r in range(3))
                obj_coords = fn.temp(VEC, f"mp_point_in_space(g, {rows})")[0]
            # Normal is object space, Reflection (the view mirrored about
            # the normal) world space, Camera Cycles' +Z-forward camera space.
            reflection = "(2.0f * dot(g->Nw, g->I) * g->Nw - g->I)"
            outs = {"Generated": ("g->generated", VEC, None), "Object": (obj_coords, VEC, None),
                    "Normal": ("g->N", VEC, None), "Camera": ("g->camera", VEC, None),
                    "Window": ("g->window", VEC, None), "Reflection": (reflection, VEC, None)}
            if node.outputs["UV"].is_linked:
                outs["UV"] = (self.uv(), VEC, None)
            return outs
        if t == "UVMAP":
            if getattr(node, "from_instancer", False):
                self.warn(node, "From Instancer is not supported; the object's own UV map is used")
            return {"UV": (self.uv(node.uv_map), VEC, None)}
        if t == "TEX_IMAGE":
            return self.emit_image(node)
        if t == "TEX_ENVIRONMENT":
            return self.emit_environment(node)
        if t == "TEX_SKY":
            return self.emit_sky(node)
        if t == "NEW_GEOMETRY":
            return self.emit_geometry(node)
        if t == "TANGENT":
            return self.emit_tangent(node)
        if t == "VECTOR_DISPLACEMENT":
            return self.emit_vector_displacement(node)
        if t == "FRESNEL":
            n = self.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
            return {"Fac": fn.temp(FLOAT, f"mp_fresnel_node(g, {self.input(node, 'IOR', FLOAT)[0]}, {n})",
                                   (0.0, 1.0))}
        if t == "LAYER_WEIGHT":
            n = self.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
            facing = fn.temp(FLOAT, "0.0f", (0.0, 1.0))
            fresnel = fn.temp(FLOAT, f"mp_layer_weight(g, {self.input(node, 'Blend', FLOAT)[0]}, {n}, &{facing[0]})",
                              (0.0, 1.0))
            return {"Fresnel": fresnel, "Facing": facing}
        if t in ("ATTRIBUTE", "VERTEX_COLOR"):
            return self.emit_attribute(node)
        if t == "LIGHT_PATH":
            return self.emit_light_path(node)
        if t == "OBJECT_INFO":
            # Per object (DeviceObject: its colour, pass index and random
            # number, export_mesh.py); the material's pass index is a constant.
            index = float(getattr(self.material, "pass_index", 0))
            outs = {"Location": ("(g->object ? (float3)(g->object->to_world[3], g->object->to_world[7], "
                                 "g->object->to_world[11]) : (float3)(0.0f))", VEC, None),
                    "Color": ("(g->object ? (float3)(g->object->color[0], g->object->color[1], g->object->color[2])"
                              " : (float3)(1.0f))", VEC, None),
                    "Alpha": ("(g->object ? g->object->color[3] : 1.0f)", FLOAT, None),
                    "Object Index": ("(g->object ? g->object->info[0] : 0.0f)", FLOAT, None),
                    "Random": ("(g->object ? g->object->info[1] : 0.0f)", FLOAT, None),
                    "Material Index": (_lit(index), FLOAT, (index, index))}
            return {node.outputs[name].identifier: value for name, value in outs.items() if name in node.outputs}
        if t == "VALUE":
            x = float(node.outputs[0].default_value)
            return {node.outputs[0].identifier: (self.param(x), FLOAT, (x, x))}
        if t == "RGB":
            return {node.outputs[0].identifier: (self.param3(node.outputs[0].default_value), VEC, None)}
        if t == "MATH":
            return self.emit_math(node)
        if t == "VECT_MATH":
            op = node.operation
            if op not in VMATH_OPS:
                self.warn(node, f"operation {op} is not supported")
                return {}
            a, b, c = (self.input(node, i, VEC)[0] for i in range(3))
            scale = self.input(node, 3, FLOAT)[0] if len(node.inputs) > 3 else "1.0f"
            val = fn.temp(FLOAT, "0.0f")
            vec = fn.temp(VEC, f"mp_vector_math({VMATH_OPS.index(op)}, {a}, {b}, {c}, {scale}, &{val[0]})")
            return {"Vector": vec, "Value": val}
        if t == "MIX_RGB":
            return self.emit_mix(node, node.blend_type, node.use_clamp, False, self.input(node, "Fac", FLOAT),
                                 self.input(node, "Color1", VEC), self.input(node, "Color2", VEC), "Color")
        if t == "MIX":
            return self.emit_mix_node(node)
        if t == "GROUP":
            return self.emit_group(node)
        if t == "HUE_SAT":
            h, sat, val, fac = (self.input(node, k, FLOAT)[0] for k in ("Hue", "Saturation", "Value", "Fac"))
            col = self.input(node, "Color", VEC)[0]
            return {"Color": fn.temp(VEC, f"mp_hue_saturation({h}, {sat}, {val}, {fac}, {col})")}
        if t == "MAP_RANGE":
            mode = node.interpolation_type
            if getattr(node, "data_type", "FLOAT") == "FLOAT_VECTOR":
                names = ("Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3", "To_Max_FLOAT3",
                         "Steps_FLOAT3")
                args = [self.by_id(node, n, VEC)[0] for n in names]
                return {"Vector": fn.temp(VEC, f"mp_map_range3({RANGE_MODES.index(mode)}, " + ", ".join(args) +
                                               f", {1 if node.clamp else 0})")}
            args = [self.input(node, i, FLOAT) for i in range(6)]
            expr = (f"mp_map_range({RANGE_MODES.index(mode)}, " + ", ".join(a[0] for a in args) +
                    f", {1 if node.clamp else 0})")
            lo, hi = args[3][2], args[4][2]
            rng = None
            if node.clamp and lo and hi and mode in ("LINEAR", "STEPPED"):
                rng = (min(lo[0], hi[0]), max(lo[1], hi[1]))
            return {"Result": fn.temp(FLOAT, expr, rng)}
        if t == "CLAMP":
            v, lo, hi = (self.input(node, i, FLOAT) for i in range(3))
            rng = (min(lo[2][0], hi[2][0]), max(lo[2][1], hi[2][1])) if lo[2] and hi[2] else None
            return {"Result": fn.temp(FLOAT, f"mp_clamp_node({1 if node.clamp_type == 'RANGE' else 0}, "
                                             f"{v[0]}, {lo[0]}, {hi[0]})", rng)}
        if t == "MAPPING":
            v = self.input(node, "Vector", VEC)[0]
            loc = self.input(node, "Location", VEC)[0] if "Location" in node.inputs else "(float3)(0.0f)"
            rot = self.input(node, "Rotation", VEC)[0] if "Rotation" in node.inputs else "(float3)(0.0f)"
            scl = self.input(node, "Scale", VEC)[0] if "Scale" in node.inputs else "(float3)(1.0f)"
            return {"Vector": fn.temp(VEC, f"mp_mapping({MAPPING_TYPES.index(node.vector_type)}, {v}, {loc}, "
                                           f"{rot}, {scl})")}
        if t == "VECT_TRANSFORM":
            spaces = ("WORLD", "OBJECT", "CAMERA")
            v = self.input(node, "Vector", VEC)[0]
            kind = ("POINT", "VECTOR", "NORMAL").index(node.vector_type)
            return {"Vector": fn.temp(VEC, f"mp_vector_transform(g, {kind}, {spaces.index(node.convert_from)}, "
                                           f"{spaces.index(node.convert_to)}, {v}, "
                                           f"{1 if self.version < 400 else 0})")}
        if t == "VALTORGB":
            return self.emit_ramp(node)
        if t in ("SEPXYZ", "SEPRGB", "SEPARATE_COLOR"):
            if t == "SEPARATE_COLOR" and node.mode != "RGB":
                self.warn(node, f"{node.mode} mode is not supported; RGB is used")
            v = fn.temp(VEC, self.input(node, 0, VEC)[0])
            outs = [o.identifier for o in node.outputs]
            return {outs[0]: (f"{v[0]}.x", FLOAT, None), outs[1]: (f"{v[0]}.y", FLOAT, None),
                    outs[2]: (f"{v[0]}.z", FLOAT, None)}
        if t in ("COMBXYZ", "COMBRGB", "COMBINE_COLOR"):
            if t == "COMBINE_COLOR" and node.mode != "RGB":
                self.warn(node, f"{node.mode} mode is not supported; RGB is used")
            x, y, z = (self.input(node, i, FLOAT)[0] for i in range(3))
            return {node.outputs[0].identifier: fn.temp(VEC, f"(float3)({x}, {y}, {z})")}
        if t == "RGBTOBW":
            return {"Val": fn.temp(FLOAT, f"mp_rgb_to_bw({self.input(node, 0, VEC)[0]})")}
        if t == "INVERT":
            fac, col = self.input(node, "Fac", FLOAT)[0], self.input(node, "Color", VEC)[0]
            return {"Color": fn.temp(VEC, f"mix({col}, (float3)(1.0f) - {col}, {fac})")}
        if t == "DISPLACEMENT":
            return self.emit_displacement(node)
        if t == "BUMP":
            return self.emit_bump(node)
        if t == "NORMAL_MAP":
            return self.emit_normal_map(node)
        if t in TEXTURE_HEADERS:
            return self.emit_texture(node)
        outs = node_textures.emit(self, node)
        if outs is not None:
            return outs
        self.warn(node, "is not supported; its outputs take their default values")
        return {}

    def emit_geometry(self, node):
        """Geometry node, in world space as Cycles': True Normal is the
        limit surface's normal (the smooth one; Micropoly's surfaces have
        no facets), Tangent the radial one about the object's Z axis."""
        for name in ("Parametric", "Pointiness", "Random Per Island"):
            if name in node.outputs and node.outputs[name].is_linked:
                self.warn(node, f"the {name} output is not supported; it gives its default")
        backfacing = self.fn.temp(FLOAT, "(float)mp_backfacing(g)", (0.0, 1.0))
        tangent = self.fn.temp(VEC, "mp_world_tangent(g, mp_radial_tangent(g))")
        return {"Position": ("mp_world_position(g)", VEC, None), "Normal": ("g->Nw", VEC, None),
                "True Normal": ("g->Nw", VEC, None), "Incoming": ("g->I", VEC, None),
                "Tangent": tangent, "Backfacing": backfacing}

    def emit_tangent(self, node):
        """Tangent node: radial about an object axis through Generated
        coordinates, or a UV map's MikkTSpace tangent (zero without one, as
        Cycles gives), in world space and orthogonal to the normal."""
        if node.direction_type == "UV_MAP":
            ta, tb = self.resources.tangent_layers(node.uv_map)
            t = f"mp_uv_tangent(g, {ta}, {tb}, 0)"
        else:
            t = f"mp_radial_tangent_axis(g, {'XYZ'.index(node.axis)})"
        return {"Tangent": self.fn.temp(VEC, f"mp_world_tangent(g, {t})")}

    def emit_attribute(self, node):
        """Attribute (Geometry type) and Color Attribute: a mesh attribute's
        value per face corner, interpolated over the surface as UVs are
        (two layers: RG and BA)."""
        if node.type == "VERTEX_COLOR":
            name = node.layer_name
        else:
            if getattr(node, "attribute_type", "GEOMETRY") != "GEOMETRY":
                self.warn(node, f"{node.attribute_type.title()} attributes are not supported; it gives zero")
                return {}
            name = node.attribute_name
        ka, kb = self.resources.attribute_layers(name)
        if ka < 0:
            return {}
        rgba = self.fn.temp("float4", f"(float4)(g->uv[{ka}].x, g->uv[{ka}].y, g->uv[{kb}].x, g->uv[{kb}].y)")[0]
        color = (f"{rgba}.xyz", VEC, None)
        # Fac: a float attribute's value, a colour's or vector's average (Cycles).
        return {"Color": color, "Vector": color, "Fac": (f"dot({rgba}.xyz, (float3)(1.0f / 3.0f))", FLOAT, None),
                "Alpha": (f"{rgba}.w", FLOAT, None)}

    def emit_light_path(self, node):
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

    def emit_math(self, node):
        op = node.operation
        if op not in MATH_OPS:
            self.warn(node, f"operation {op} is not supported")
            return {}
        a, b, c = (self.input(node, i, FLOAT) for i in range(3))
        expr = f"mp_math({MATH_OPS.index(op)}, {a[0]}, {b[0]}, {c[0]})"
        rng = None
        ra, rb, rc = a[2], b[2], c[2]
        if ra and rb:
            if op == "ADD":
                rng = (ra[0] + rb[0], ra[1] + rb[1])
            elif op == "SUBTRACT":
                rng = (ra[0] - rb[1], ra[1] - rb[0])
            elif op in ("MULTIPLY", "MULTIPLY_ADD"):
                prods = [x * y for x in ra for y in rb]
                rng = (min(prods), max(prods))
                if op == "MULTIPLY_ADD":
                    rng = (rng[0] + rc[0], rng[1] + rc[1]) if rc else None
            elif op in ("MINIMUM", "MAXIMUM"):
                f = min if op == "MINIMUM" else max
                rng = (f(ra[0], rb[0]), f(ra[1], rb[1]))
        if op in ("SINE", "COSINE"):
            rng = (-1.0, 1.0)
        if node.use_clamp:
            expr = f"mp_nl_clamp01({expr})"
            rng = (max(0.0, rng[0]), min(1.0, rng[1])) if rng else (0.0, 1.0)
        return {node.outputs[0].identifier: self.fn.temp(FLOAT, expr, rng)}

    def emit_mix(self, node, mode, clamp_result, clamp_factor, fac, a, b, out_id):
        if mode not in BLEND_MODES:
            self.warn(node, f"blend mode {mode} is not supported; Mix is used")
            mode = "MIX"
        t = f"mp_nl_clamp01({fac[0]})" if clamp_factor else fac[0]
        expr = f"mp_blend({BLEND_MODES.index(mode)}, {t}, {a[0]}, {b[0]})"
        if clamp_result:
            expr = f"mp_nl_clamp01_3({expr})"
        return {out_id: self.fn.temp(VEC, expr)}

    def emit_mix_node(self, node):
        dt = node.data_type
        if dt == "FLOAT":
            fac = self.by_id(node, "Factor_Float", FLOAT)
            a, b = self.by_id(node, "A_Float", FLOAT), self.by_id(node, "B_Float", FLOAT)
            t = f"mp_nl_clamp01({fac[0]})" if node.clamp_factor else fac[0]
            return {"Result_Float": self.fn.temp(FLOAT, f"mix({a[0]}, {b[0]}, {t})")}
        if dt == "VECTOR":
            uniform = getattr(node, "factor_mode", "UNIFORM") == "UNIFORM"
            fac = self.by_id(node, "Factor_Float" if uniform else "Factor_Vector", FLOAT if uniform else VEC)
            a, b = self.by_id(node, "A_Vector", VEC), self.by_id(node, "B_Vector", VEC)
            t = fac[0]
            if node.clamp_factor:
                t = f"mp_nl_clamp01({t})" if uniform else f"mp_nl_clamp01_3({t})"
            return {"Result_Vector": self.fn.temp(VEC, f"{a[0]} + ({b[0]} - {a[0]}) * {t}")}
        fac = self.by_id(node, "Factor_Float", FLOAT)
        a, b = self.by_id(node, "A_Color", VEC), self.by_id(node, "B_Color", VEC)
        return self.emit_mix(node, node.blend_type, node.clamp_result, node.clamp_factor, fac, a, b, "Result_Color")

    def emit_ramp(self, node):
        ramp = node.color_ramp
        if ramp.color_mode != "RGB":
            self.warn(node, f"{ramp.color_mode} color mode is not supported; RGB is used")
        interp = {"LINEAR": 0, "CONSTANT": 1, "EASE": 2}.get(ramp.interpolation)
        if interp is None:
            self.warn(node, f"{ramp.interpolation} interpolation is not supported; Linear is used")
            interp = 0
        elems = sorted(ramp.elements, key=lambda e: e.position)
        n = len(elems)
        fac = self.input(node, "Fac", FLOAT)[0]
        k = self.fn.counter
        self.fn.counter += 1
        pos = ", ".join(self.param(e.position) for e in elems)
        cols = ", ".join(self.param4(e.color) for e in elems)
        self.fn.lines.append(f"  const float ramp_pos{k}[{n}] = {{{pos}}};")
        self.fn.lines.append(f"  const float4 ramp_col{k}[{n}] = {{{cols}}};")
        c = self.fn.temp("float4", f"mp_color_ramp({interp}, {n}, ramp_pos{k}, ramp_col{k}, {fac})")
        return {"Color": (f"{c[0]}.xyz", VEC, None), "Alpha": (f"{c[0]}.w", FLOAT, (0.0, 1.0))}

    def emit_displacement(self, node):
        if node.inputs["Normal"].is_linked:
            self.warn(node, "a linked Normal input is not supported; the surface normal is used")
        h, mid, scale = (self.input(node, k, FLOAT) for k in ("Height", "Midlevel", "Scale"))
        self.displacement_bounds.append(_displacement_node_bound(h, mid, scale, 1.0))
        amount = f"(({h[0]}) - ({mid[0]})) * ({scale[0]})"
        if getattr(node, "space", "OBJECT") == "WORLD":
            # World units along the world-space normal: the bound is in world units too.
            self.displacement_world = True
            return {"Displacement": self.fn.temp(VEC, f"mp_displacement_world(g, {amount})")}
        return {"Displacement": self.fn.temp(VEC, f"{amount} * g->N")}

    def emit_vector_displacement(self, node):
        """Vector Displacement: (Vector - Midlevel) x Scale in tangent space
        (x along the active UV map's tangent, y along the normal, z along
        the bitangent, as Cycles reads it), object space or world space."""
        vec = self.input(node, "Vector", VEC)
        mid, scale = self.input(node, "Midlevel", FLOAT), self.input(node, "Scale", FLOAT)
        self.displacement_bounds.append(_displacement_node_bound(vec, mid, scale, math.sqrt(3.0)))
        d = f"((({vec[0]}) - (float3)({mid[0]})) * ({scale[0]}))"
        if node.space == "TANGENT":
            ta, tb = self.resources.tangent_layers("")
            if ta < 0:
                self.warn(node, "the UV layers ran out, so it has no tangents; only the normal component "
                                "displaces")
            expr = f"mp_vector_displacement_tangent(g, {ta}, {tb}, {d})"
        elif node.space == "WORLD":
            self.displacement_world = True
            expr = f"mp_world_dir_to_object(g, {d})"
        else:
            expr = d
        return {"Displacement": self.fn.temp(VEC, expr)}

    def emit_texture(self, node):
        t, fn, ver = node.type, self.fn, self.version
        self.headers.add(TEXTURE_HEADERS[t])
        inp = lambda name, default="0.0f": self.input(node, name, FLOAT)[0] if name in node.inputs else default
        vec = self.vector_or_generated(node)
        if t == "TEX_NOISE":
            dims = _dims(node.noise_dimensions)
            ntype = FRACTAL_TYPES.index(getattr(node, "noise_type", "FBM"))
            normalize = 1 if getattr(node, "normalize", True) else 0
            fac, col = fn.temp(FLOAT, "0.0f", FAC_RANGE), fn.temp(VEC, "(float3)(0.0f)")
            fn.lines.append(f"  mp_tex_noise({vec}, {inp('W')}, {dims}, {ntype}, {normalize}, {inp('Scale')}, "
                            f"{inp('Detail')}, {inp('Roughness')}, {inp('Lacunarity', '2.0f')}, "
                            f"{inp('Offset')}, {inp('Gain', '1.0f')}, {inp('Distortion')}, {ver}, "
                            f"&{fac[0]}, &{col[0]});")
            return {"Fac": fac, "Color": col}
        if t == "TEX_MUSGRAVE":
            dims = _dims(node.musgrave_dimensions)
            mtype = FRACTAL_TYPES.index(node.musgrave_type)
            expr = (f"mp_tex_musgrave({vec}, {inp('W')}, {dims}, {mtype}, {inp('Scale')}, {inp('Detail')}, "
                    f"{inp('Dimension')}, {inp('Lacunarity')}, {inp('Offset')}, {inp('Gain')}, {ver})")
            return {"Fac": fn.temp(FLOAT, expr)}
        if t == "TEX_WAVE":
            wtype = 0 if node.wave_type == "BANDS" else 1
            direction = (["X", "Y", "Z", "DIAGONAL"].index(node.bands_direction) if wtype == 0 else
                         ["X", "Y", "Z", "SPHERICAL"].index(node.rings_direction))
            profile = ["SIN", "SAW", "TRI"].index(node.wave_profile)
            fac, col = fn.temp(FLOAT, "0.0f", FAC_RANGE), fn.temp(VEC, "(float3)(0.0f)")
            fn.lines.append(f"  mp_tex_wave({vec}, {wtype}, {direction}, {profile}, {inp('Scale')}, "
                            f"{inp('Distortion')}, {inp('Detail')}, {inp('Detail Scale')}, "
                            f"{inp('Detail Roughness')}, {inp('Phase Offset')}, {ver}, &{fac[0]}, &{col[0]});")
            return {"Fac": fac, "Color": col}
        # Voronoi
        dims = _dims(node.voronoi_dimensions)
        feature = VORONOI_FEATURES.index(node.feature)
        metric = VORONOI_METRICS.index(node.distance)
        normalize = 1 if getattr(node, "normalize", False) else 0
        # F1 lies within the point's own cell: at most the cell diagonal away.
        near = node.feature in ("F1", "SMOOTH_F1") and node.distance == "EUCLIDEAN"
        dist = fn.temp(FLOAT, "0.0f", (0.0, math.sqrt(dims)) if near else None)
        col = fn.temp(VEC, "(float3)(0.0f)")
        pos, w, rad = fn.temp(VEC, "(float3)(0.0f)"), fn.temp(FLOAT, "0.0f"), fn.temp(FLOAT, "0.0f")
        fn.lines.append(f"  mp_tex_voronoi({vec}, {inp('W')}, {dims}, {feature}, {metric}, {inp('Scale')}, "
                        f"{inp('Detail')}, {inp('Roughness', '0.5f')}, {inp('Lacunarity', '2.0f')}, "
                        f"{inp('Smoothness', '1.0f')}, {inp('Exponent', '0.5f')}, {inp('Randomness', '1.0f')}, "
                        f"{normalize}, {ver}, &{dist[0]}, &{col[0]}, &{pos[0]}, &{w[0]}, &{rad[0]});")
        return {"Distance": dist, "Color": col, "Position": pos, "W": w, "Radius": rad}

    def height_function(self, node, key):
        """A helper function evaluating input `key` of `node` for any globals."""
        outer = self.fn
        name = f"mp_height_{len(self.helpers)}"
        self.helpers.append(None)  # reserve the slot: nested heights get later ones
        slot = len(self.helpers) - 1
        text = self._function(f"float {name}(const MpNodeGlobals* g)",
                              lambda: f"  return {self.input(node, key, FLOAT)[0]};\n")
        self.helpers[slot] = text
        self.fn = outer
        return name

    def emit_bump(self, node):
        """Bump: heights at this vertex and its grid neighbours (mp_bump)."""
        self.uses_neighbours = True
        strength = self.input(node, "Strength", FLOAT)[0]
        distance = self.input(node, "Distance", FLOAT)[0]
        n_in = self.input(node, "Normal", VEC)[0] if node.inputs["Normal"].is_linked else "g->Nw"
        if not node.inputs["Height"].is_linked:
            return {"Normal": (n_in, VEC, None)}
        h = self.height_function(node, "Height")
        invert = 1 if node.invert else 0
        return {"Normal": self.fn.temp(VEC, f"mp_bump(g, {h}(g), g->dx ? {h}(g->dx) : 0.0f, "
                                            f"g->dy ? {h}(g->dy) : 0.0f, {strength}, {distance}, {invert}, {n_in})")}

    def emit_normal_map(self, node):
        """Normal Map: tangent space from the UV map's tangents (mp_normal_map_tangent),
        or object space."""
        strength = self.input(node, "Strength", FLOAT)[0]
        color = self.input(node, "Color", VEC)[0]
        if node.space == "TANGENT":
            self.uses_neighbours = True  # the tangent from UV differences, where there are none
            uv = self.resources.uv_layer(node.uv_map)
            ta, tb = self.resources.tangent_layers(node.uv_map)
            # Blender 4.0 scales the map's tilt by Strength instead of blending normals.
            v4 = 1 if self.version >= 400 else 0
            expr = f"mp_normal_map_tangent(g, {uv}, {ta}, {tb}, {strength}, {color}, {v4})"
        else:
            blender = 1 if node.space.startswith("BLENDER") else 0
            world = 1 if node.space in ("WORLD", "BLENDER_WORLD") else 0
            expr = f"mp_normal_map_object(g, {blender}, {world}, {strength}, {color})"
        return {"Normal": self.fn.temp(VEC, expr)}

    def emit_image(self, node):
        self.headers.add("mp_tex_image.h")
        index, value_range = self.resources.image(node.image, lambda what: self.warn(node, what))
        vec = self.input(node, "Vector", VEC)[0] if node.inputs["Vector"].is_linked else self.uv()
        interp = IMAGE_INTERPOLATION.get(node.interpolation, 0)
        ext = IMAGE_EXTENSION.get(node.extension, 0)
        images = f"g->images, g->image_count, g->texels, {index}"
        if node.projection == "BOX":
            # Blended by the object-space normal, as Cycles does.
            blend = self.param(float(node.projection_blend))
            rgba = self.fn.temp("float4", f"mp_tex_image_box({images}, {vec}, g->N, {blend}, {interp}, {ext})")[0]
        else:
            if node.projection in ("SPHERE", "TUBE"):
                vec = self.fn.temp("float2", f"mp_image_{node.projection.lower()}_uv({vec})")[0]
            rgba = self.fn.temp("float4", f"mp_tex_image({images}, ({vec}).x, ({vec}).y, {interp}, {ext})")[0]
        # Cycles hands out colour premultiplied by alpha unless the Alpha
        # output is used (or alpha is channel-packed, ignored, or data).
        image = node.image
        straight = node.outputs["Alpha"].is_linked or image is None or image.alpha_mode in ("CHANNEL_PACKED", "NONE") \
            or image.colorspace_settings.is_data
        color = f"{rgba}.xyz" if straight else f"({rgba}.xyz * {rgba}.w)"
        rng = value_range
        if rng is not None and not straight:  # times an alpha in [0, 1]
            rng = (min(rng[0], 0.0), max(rng[1], 0.0))
        return {"Color": (color, VEC, rng), "Alpha": (f"{rgba}.w", FLOAT, (0.0, 1.0))}

    def emit_environment(self, node):
        """An Environment Texture: the image at a direction (the world's
        own by default), equirectangular or mirror ball, wrapping in longitude."""
        self.headers.add("mp_tex_image.h")
        index, value_range = self.resources.image(node.image, lambda what: self.warn(node, what))
        vec = self.input(node, "Vector", VEC)[0] if node.inputs["Vector"].is_linked else "g->generated"
        proj = "mirror_ball" if node.projection == "MIRROR_BALL" else "equirect"
        uv = self.fn.temp("float2", f"mp_env_{proj}_uv({vec})")[0]
        interp = IMAGE_INTERPOLATION.get(node.interpolation, 0)
        images = f"g->images, g->image_count, g->texels, {index}"
        rgba = self.fn.temp("float4", f"mp_tex_image({images}, ({uv}).x, ({uv}).y, {interp}, 0)")[0]
        return {"Color": (f"{rgba}.xyz", VEC, value_range)}

    def emit_sky(self, node):
        """A Sky Texture of a physical model (Nishita before 5.0; Single and
        Multiple Scattering in 5.0): a texture precomputed by the native
        module as Cycles does, and the sun's disc (kernels/textures/mp_tex_sky.h)."""
        sky_type = node.sky_type
        if sky_type not in SKY_MODELS:
            # Blender's default world grey stands in for the sky.
            self.warn(node, f"the {sky_type.replace('_', ' ').title()} sky model is not supported; it gives grey")
            return {"Color": ("(float3)(0.050876f)", VEC, None)}
        from . import _native  # the precomputation is native; compiling alone needs no module

        self.headers.add("mp_tex_sky.h")
        params = dict(model=sky_type, sun_disc=bool(node.sun_disc), sun_size=float(node.sun_size),
                      sun_intensity=float(node.sun_intensity), sun_elevation=float(node.sun_elevation),
                      sun_rotation=float(node.sun_rotation), altitude=float(node.altitude),
                      air=float(node.air_density),
                      dust=float(getattr(node, "aerosol_density", getattr(node, "dust_density", 1.0))),
                      ozone=float(node.ozone_density))
        spread = WORLD_SUN_SPREAD if self.world else 0.0
        sun = _native.nishita_sky_sun(spread=spread, **params)
        key = ("sky",) + tuple(sorted(params.items()))
        index = self.resources.array_image(key, lambda: _native.nishita_sky_texture(**params)[0])
        # The node's Vector socket is hidden in every version (its lookup by
        # name fails from 4.0); when it is linked all the same, it is the direction.
        vector = next((s for s in node.inputs if s.identifier == "Vector"), None)
        vec = self.input(node, list(node.inputs).index(vector), VEC)[0] if vector is not None and vector.is_linked \
            else "g->generated"
        name = f"sky{self.fn.counter}"
        self.fn.counter += 1
        fields = [self.param3(sun["sun_bottom"]), self.param3(sun["sun_top"]), self.param3(sun["sun_flux"])]
        fields += [self.param(sun[k]) for k in ("sun_elevation", "sun_rotation", "sun_diameter", "sun_intensity",
                                                "earth_angle", "spread")]
        fields.append(str(int(sun["layout"])))
        self.fn.lines.append(f"  MpSky {name} = {{{', '.join(fields)}}};")
        images = f"g->images, g->image_count, g->texels, {index}"
        return {"Color": self.fn.temp(VEC, f"mp_tex_sky({images}, {vec}, &{name})")}

    # ---- the world ------------------------------------------------------------
    def compile_world(self, output):
        """The world program: the shader tree at World Output `output`'s
        Surface as emission for each direction (material_program.cl,
        bake_world): Backgrounds (and Emissions) give their colour times
        strength, Mix and Add Shaders weigh and sum them, as in Cycles.
        Returns the source; its node values are then in self.params."""
        self.world = True
        disp_src = "float3 mp_node_displacement(const MpNodeGlobals* g) {\n  return (float3)(0.0f);\n}\n"

        def surface_body():
            self.shader_input(output, "Surface", "(float3)(1.0f)")
            return ""
        surf_src = self._function("void mp_node_surface(const MpNodeGlobals* g, MpSurface* s)", surface_body)
        includes = "".join(f'#include "textures/{h}"\n' for h in sorted(self.headers))
        return includes + "".join(self.helpers) + disp_src + surf_src

    # ---- the material -----------------------------------------------------------
    def _function(self, header, body_fn):
        self.fn = _Function()
        result = body_fn()
        text = header + " {\n" + "\n".join(self.fn.lines) + ("\n" if self.fn.lines else "") + result + "}\n"
        return text

    def compile(self):
        out = active_output(self.material)
        if out is None:
            return None
        method = getattr(self.material, "displacement_method", None)
        if method is None:
            method = getattr(getattr(self.material, "cycles", None), "displacement_method", "BUMP")
        disp_socket = out.inputs["Displacement"]
        displaces = disp_socket.is_linked and method in ("DISPLACEMENT", "BOTH")
        # Bump only: the displacement tilts shading normals (as a Bump node of
        # distance 1 on the height along the normal, the way Cycles turns
        # displacement into bump) and leaves the geometry where it is.
        bump_only = disp_socket.is_linked and method == "BUMP"
        surface = out.inputs["Surface"]
        shader = self._linked_node(surface)
        constant = shader is None or _constant_shader(shader)
        bump_line = ""
        if bump_only:
            self.uses_neighbours = True
            h = "dot(mp_node_displacement({0}), g->N)"
            bump_line = (f"  mp_surface_set_normal(s, mp_world_normal_to_object(g, mp_bump(g, {h.format('g')}, "
                         f"g->dx ? {h.format('g->dx')} : 0.0f, g->dy ? {h.format('g->dy')} : 0.0f, 1.0f, 1.0f, 0, "
                         f"g->Nw)));\n")
        shades = not constant or bool(bump_line)
        if not displaces and not shades:
            return None

        self.displacement_bounds = []  # one per Displacement / Vector Displacement node reached (None: unknown)
        disp_src = self._function("float3 mp_node_displacement(const MpNodeGlobals* g)",
                                  lambda: "  return " + self.input(out, "Displacement", VEC)[0] + ";\n"
                                  if displaces or bump_only else "  return (float3)(0.0f);\n")
        bound = self._displacement_bound(displaces)

        def surface_body():
            self.fn.lines.append(bump_line.rstrip("\n"))
            if shader is None:
                # No shader: Cycles renders the surface black.
                return ""
            self.shader_input(out, "Surface", "(float3)(1.0f)")
            return ""
        surf_src = self._function("void mp_node_surface(const MpNodeGlobals* g, MpSurface* s)", surface_body)
        if self.closures > MAX_CLOSURES:
            self.warnings.append(f"material '{self.material.name}': its shader tree can add up to {self.closures} "
                                 f"closures at a point; past {MAX_CLOSURES} the last are left out")
        includes = "".join(f'#include "textures/{h}"\n' for h in sorted(self.headers))
        if self.uses_neighbours:
            includes = "#define MP_NODE_USES_NEIGHBOURS 1\n" + includes
        if self.uses_thin_film:
            # Ahead of the kernel headers (program_cache.cpp hoists it).
            includes = "#define MP_NODE_USES_THIN_FILM 1\n" + includes
        if self.uses_subsurface_walk:
            includes = "#define MP_NODE_USES_SUBSURFACE_WALK 1\n" + includes
        source = includes + "".join(self.helpers) + disp_src + surf_src
        return CompiledMaterial(source, displaces, shades, bound, displaces and self.displacement_world,
                                alpha=self.transparent, params=self.params)

    # ---- shader trees -> closures ------------------------------------------------
    @staticmethod
    def _follow(socket):
        return linked_from(socket)

    def _linked_node(self, socket):
        return linked_from(socket)[0]

    def shader_input(self, node, key, weight):
        """Adds the closures of the shader linked into node.inputs[key],
        each scaled by `weight` (a float3 expression)."""
        socket = node.inputs[key] if isinstance(key, int) else node.inputs.get(key)
        if socket is None:
            return
        src, out = self._follow(socket)
        if src is None:
            return
        if getattr(src, "mute", False):
            # A muted node passes its first shader input through.
            first = next((i for i, s in enumerate(src.inputs) if s.type == "SHADER"), None)
            if first is not None:
                self.shader_input(src, first, weight)
            return
        if src.type == "GROUP_INPUT":
            if not self.groups:
                return
            group = self.groups.pop()
            try:
                index = next((i for i, s in enumerate(group.inputs) if s.identifier == out.identifier), None)
                if index is not None:
                    self.shader_input(group, index, weight)
            finally:
                self.groups.append(group)
            return
        if src.type == "GROUP":
            tree = src.node_tree
            outputs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"] if tree is not None else []
            active = [n for n in outputs if getattr(n, "is_active_output", False)] or outputs
            if not active:
                self.warn(src, "has no node tree or no Group Output; it adds nothing to the surface")
                return
            index = next((i for i, s in enumerate(active[0].inputs) if s.identifier == out.identifier), None)
            if index is None:
                return
            self.groups.append(src)
            try:
                self.shader_input(active[0], index, weight)
            finally:
                self.groups.pop()
            return
        self.emit_shader(src, weight)

    def _normal_slot(self, node, key="Normal"):
        """The normal slot of a BSDF's Normal input: 0 (the surface's) unless
        linked. Node values are world space, closure normals object space."""
        socket = node.inputs.get(key)
        if socket is None or not socket.is_linked:
            return "0"
        expr = f"mp_world_normal_to_object(g, {self.input(node, key, VEC)[0]})"
        return self.fn.temp("int", f"mp_surface_normal_slot(s, {expr}, {self._normal_input_mode()})")[0]

    def _slot_normal(self, slot):
        return "g->N" if slot == "0" else f"s->normal[{slot}]"

    def _tangent(self, node):
        """A BSDF's Tangent input (a world-space node value, turned into
        object space as the closures' normals), or the Tangent node's
        default: radial about the object's Z axis through Generated
        coordinates."""
        socket = node.inputs.get("Tangent")
        if socket is not None and socket.is_linked:
            return f"mp_world_dir_to_object(g, {self.input(node, 'Tangent', VEC)[0]})"
        return "mp_radial_tangent(g)"

    @staticmethod
    def _unlinked_zero(node, *names):
        """Whether the first of `names` that the node has is an unlinked
        socket at 0 (or the node has none): a value the tree's structure
        may depend on, as it decides whether code is needed at all."""
        for name in names:
            socket = node.inputs.get(name)
            if socket is not None:
                return not socket.is_linked and float(socket.default_value) == 0.0
        return True

    def _anisotropy_tangent(self, node, slot):
        """The tangent an anisotropic lobe stretches along (zero while the
        anisotropy is the constant 0), turned about its normal by the node's
        Rotation."""
        if self._unlinked_zero(node, "Anisotropy"):
            return "(float3)(0.0f)"
        return f"mp_rotate_tangent({self._tangent(node)}, {self._slot_normal(slot)}, {self._f(node, 'Rotation')})"

    def _f(self, node, *names, default="0.0f"):
        for name in names:
            if name in node.inputs:
                return self.input(node, name, FLOAT)[0]
        return default

    def _c(self, node, *names, default="(float3)(0.0f)"):
        for name in names:
            if name in node.inputs:
                return self.input(node, name, VEC)[0]
        return default

    def _weighted(self, weight, *factors):
        return self.fn.temp(VEC, " * ".join((weight,) + factors))[0]

    def emit_shader(self, node, weight):
        t = node.type
        add = self.fn.lines.append
        if t == "MIX_SHADER":
            fac = self.fn.temp(FLOAT, f"mp_nl_clamp01({self.input(node, 0, FLOAT)[0]})")[0]
            self.shader_input(node, 1, self._weighted(weight, f"(1.0f - {fac})"))
            self.shader_input(node, 2, self._weighted(weight, fac))
            return
        if t == "ADD_SHADER":
            self.shader_input(node, 0, weight)
            self.shader_input(node, 1, weight)
            return
        if t in ("EMISSION", "BACKGROUND"):
            add(f"  mp_add_emission(s, {weight} * {self._c(node, 'Color')} * {self._f(node, 'Strength')});")
            return
        if self.world:
            # A world shows and sends only light: Cycles renders other
            # shaders there as nothing.
            self.warn(node, "is not a Background or Emission; a world gives no light through it")
            return
        if t == "BSDF_PRINCIPLED":
            self.closures += 5  # its most layers at once (coat, sheen, metal, glass, specular; diffuse replaces one)
            return self.emit_principled(node, weight)
        if t == "BSDF_TRANSPARENT":
            self.transparent = True
            add(f"  mp_add_transparent(s, {weight} * {self._c(node, 'Color')});")
            return
        if t == "HOLDOUT":
            add(f"  mp_add_holdout(s, {weight});")
            return
        self.closures += 2 if t == "BSDF_GLASS" else 1
        slot = self._normal_slot(node)
        color = self._c(node, "Color", "Base Color", default="(float3)(0.8f)")
        if t == "BSDF_DIFFUSE" and self.version >= 403:
            # 4.3 and later: Oren-Nayar with EON's multiple scattering, which
            # depends on the colour alone (not the weight above it).
            add(f"  {{ float3 albedo_ = {color}; mp_add_diffuse_eon(s, {weight} * albedo_, albedo_, {slot}, "
                f"{self._f(node, 'Roughness')}); }}")
        elif t == "BSDF_DIFFUSE":
            add(f"  mp_add_diffuse(s, {weight} * {color}, {slot}, {self._f(node, 'Roughness')});")
        elif t == "BSDF_TRANSLUCENT":
            add(f"  mp_add_translucent(s, {weight} * {color}, {slot});")
        elif t == "SUBSURFACE_SCATTERING" and self._subsurface_model(node) != "MP_SSS_LAMBERT":
            # 4.x's random walk: the albedo it returns (kernels/closures/mp_subsurface.h).
            self.uses_subsurface_walk = True
            radius = f"{self._c(node, 'Radius', default='(float3)(1.0f)')} * {self._f(node, 'Scale', default='1.0f')}"
            add(f"  {{ float3 albedo_ = {color}; mp_add_subsurface_walk(s, {weight} * albedo_, albedo_, {radius}, "
                f"fabs(mp_view_cos(g, {self._slot_normal(slot)})), clamp({self._f(node, 'Roughness', default='1.0f')}, "
                f"0.0f, 1.0f), {self._f(node, 'IOR', default='1.4f')}, {self._subsurface_model(node)}, {slot}); }}")
        elif t == "SUBSURFACE_SCATTERING":
            add(f"  mp_add_subsurface(s, {weight} * {color}, {slot});")
        elif t in ("BSDF_GLOSSY", "BSDF_ANISOTROPIC"):
            dist = getattr(node, "distribution", "GGX")
            if dist in ("BECKMANN", "ASHIKHMIN_SHIRLEY"):
                self.warn(node, f"the {dist.replace('_', '-').title()} distribution is shaded as GGX")
            rough = "0.0f" if dist == "SHARP" else self._f(node, "Roughness")
            aniso = self._f(node, "Anisotropy")
            tangent = self._anisotropy_tangent(node, slot)
            add(f"  mp_add_glossy(s, {weight} * {color}, {slot}, {rough}, {aniso}, {tangent}, MP_FRESNEL_NONE, "
                f"(float3)(0.0f), (float3)(1.0f), {1 if dist == 'MULTI_GGX' else 0});")
        elif t in ("BSDF_GLASS", "BSDF_REFRACTION"):
            dist = getattr(node, "distribution", "GGX")
            if dist == "BECKMANN":
                self.warn(node, "the Beckmann distribution is shaded as GGX")
            rough = "0.0f" if dist == "SHARP" else self._f(node, "Roughness")
            ior = self._f(node, "IOR", default="1.45f")
            if t == "BSDF_GLASS":
                add(f"  mp_add_glass_tinted(s, {weight} * {color}, {color}, {slot}, {rough}, {ior}, "
                    f"{1 if dist == 'MULTI_GGX' else 0});")
            else:
                add(f"  mp_add_refraction_tinted(s, {weight} * {color}, {color}, {slot}, {rough}, {ior}, 0);")
        elif t in ("BSDF_VELVET", "BSDF_SHEEN"):
            model = "MP_SHEEN_MICROFIBER" if getattr(node, "distribution", "ASHIKHMIN") == "MICROFIBER" \
                else "MP_SHEEN_ASHIKHMIN"
            rough = self._f(node, "Roughness", "Sigma", default="0.5f")
            add(f"  mp_add_sheen(s, {weight} * {color}, {slot}, {rough}, {model});")
        elif t == "BSDF_TOON":
            glossy = 1 if node.component == "GLOSSY" else 0
            add(f"  mp_add_toon(s, {weight} * {color}, {slot}, {self._f(node, 'Size')}, {self._f(node, 'Smooth')}, "
                f"{glossy});")
        elif t == "BSDF_METALLIC":
            if getattr(node, "distribution", "GGX") == "BECKMANN":
                self.warn(node, "the Beckmann distribution is shaded as GGX")
            if getattr(node, "fresnel_type", "F82") == "F82":
                f0 = f"mp_nl_clamp01_3({color})"
                tint = f"mp_nl_clamp01_3({self._c(node, 'Edge Tint', default='(float3)(1.0f)')})"
            else:
                # Physical Conductor: its reflectance at normal incidence
                # from IOR n and extinction k, ((n-1)^2 + k^2) / ((n+1)^2 + k^2),
                # with no dip towards grazing.
                self.warn(node, "the Physical Conductor Fresnel is shaded as F82 tint from its reflectance at "
                                "normal incidence")
                f0 = self.fn.temp(VEC, f"mp_conductor_f0({self._c(node, 'IOR')}, {self._c(node, 'Extinction')})")[0]
                tint = "(float3)(1.0f)"
            aniso = self._f(node, "Anisotropy")
            tangent = self._anisotropy_tangent(node, slot)
            self._note_thin_film(node)
            film = f"{self._f(node, 'Thin Film Thickness')}, {self._f(node, 'Thin Film IOR', default='1.33f')}"
            add(f"  mp_add_glossy_aspect(s, {weight}, {slot}, {self._f(node, 'Roughness')}, {aniso}, {tangent}, "
                f"MP_FRESNEL_F82, {f0}, {tint}, {1 if getattr(node, 'distribution', 'GGX') == 'MULTI_GGX' else 0}, "
                f"{film});")
        else:
            # Anything else (hair, volumes, ray portals, shaders of newer
            # Blender): a diffuse of its Color input, and a warning.
            self.warn(node, "is not supported; it is shaded as a Diffuse BSDF of its color")
            add(f"  mp_add_diffuse(s, {weight} * {color}, {slot}, 0.0f);")

    def _note_thin_film(self, node):
        """A Thin Film Thickness that is linked or above 0 makes the program
        compile the film's code (kernels/closures/mp_closures.h, MP_THIN_FILM)."""
        thin = node.inputs.get("Thin Film Thickness")
        if thin is not None and (thin.is_linked or float(thin.default_value) > 0.0):
            self.uses_thin_film = True

    def emit_principled(self, node, weight):
        """Principled BSDF: every input, in the running Blender's layout
        (kernels/closures/mp_principled.h)."""
        v4 = self.version >= 400
        f, c = self._f, self._c
        slot = self._normal_slot(node)
        coat_slot = self._normal_slot(node, "Coat Normal" if v4 else "Clearcoat Normal")
        n, cn = self._slot_normal(slot), self._slot_normal(coat_slot)
        p = f"pr{self.fn.counter}"
        self.fn.counter += 1
        alpha = node.inputs.get("Alpha")
        if alpha is not None and (alpha.is_linked or float(alpha.default_value) < 1.0):
            self.transparent = True
        self._note_thin_film(node)
        fields = {
            "base_color": c(node, "Base Color"), "metallic": f(node, "Metallic"), "roughness": f(node, "Roughness"),
            "ior": f(node, "IOR", default="1.45f"), "alpha": f(node, "Alpha", default="1.0f"),
            "specular": f(node, "Specular IOR Level", "Specular", default="0.5f"),
            "specular_tint": c(node, "Specular Tint", default="(float3)(1.0f)") if v4
            else f"(float3)({f(node, 'Specular Tint')})",
            "anisotropy": f(node, "Anisotropic"), "anisotropic_rotation": f(node, "Anisotropic Rotation"),
            "transmission": f(node, "Transmission Weight", "Transmission"),
            "transmission_roughness": f(node, "Transmission Roughness"),
            "coat": f(node, "Coat Weight", "Clearcoat"), "coat_roughness": f(node, "Coat Roughness",
                                                                             "Clearcoat Roughness"),
            "coat_ior": f(node, "Coat IOR", default="1.5f"), "coat_tint": c(node, "Coat Tint", default="(float3)(1.0f)"),
            "sheen": f(node, "Sheen Weight", "Sheen"), "sheen_roughness": f(node, "Sheen Roughness", default="0.5f"),
            "sheen_tint": c(node, "Sheen Tint", default="(float3)(1.0f)") if v4
            else f"(float3)({f(node, 'Sheen Tint')})",
            "subsurface": f(node, "Subsurface Weight", "Subsurface"),
            "diffuse_roughness": f(node, "Diffuse Roughness") if v4 else "0.0f",
            "thin_film": f(node, "Thin Film Thickness"), "thin_film_ior": f(node, "Thin Film IOR", default="1.33f"),
            # Cycles colours metal by the film from Blender 5.0 on.
            "film_on_metal": "1" if self.version >= 500 else "0",
            "subsurface_color": c(node, "Subsurface Color", default="(float3)(0.0f)"),
            "subsurface_radius": f"{c(node, 'Subsurface Radius', default='(float3)(1.0f)')} * "
                                 f"{f(node, 'Subsurface Scale', default='0.05f')}",
            "subsurface_ior": f(node, "Subsurface IOR", default="1.4f"),
            "subsurface_model": self._subsurface_model(node),
            "emission": f"{c(node, 'Emission Color', 'Emission')} * {f(node, 'Emission Strength', default='1.0f')}",
            "slot": slot, "coat_slot": coat_slot, "v4": "1" if v4 else "0", "retro": "0" if v4 else "1",
            "multiscatter": "1" if getattr(node, "distribution", "GGX") == "MULTI_GGX" else "0",
        }
        fields["tangent"] = "(float3)(0.0f)" if self._unlinked_zero(node, "Anisotropic") else self._tangent(node)
        if fields["subsurface_model"] != "MP_SSS_LAMBERT" and not self._unlinked_zero(node, "Subsurface Weight"):
            self.uses_subsurface_walk = True
        add = self.fn.lines.append
        add(f"  MpPrincipled {p};")
        for k, v in fields.items():
            add(f"  {p}.{k} = {v};")
        add(f"  {p}.nv = fabs(mp_view_cos(g, {n}));")
        add(f"  {p}.coat_nv = fabs(mp_view_cos(g, {cn}));")
        add(f"  mp_add_principled(s, {weight}, &{p}, {n});")

    def _subsurface_model(self, node):
        """How a subsurface closure returns light (kernels/closures/mp_subsurface.h):
        from 4.0 on Cycles' random walk enters through a rough boundary and
        returns less or more than its Color with the view's angle; Blender
        3.x's walk and Christensen-Burley return the Color (Lambert)."""
        method = getattr(node, "subsurface_method", None) or getattr(node, "falloff", "RANDOM_WALK")
        if self.version < 400 or method not in ("RANDOM_WALK", "RANDOM_WALK_SKIN"):
            return "MP_SSS_LAMBERT"
        return "MP_SSS_SKIN" if method == "RANDOM_WALK_SKIN" else "MP_SSS_WALK"

    def _normal_input_mode(self):
        """How Cycles treats a BSDF's Normal input in the running Blender:
        3.x keeps it from reflecting the view below the surface and shadows
        its diffuse light by the smooth surface (Chiang et al.); 4.0 and later
        reject light from the wrong side of the smooth surface and, with the
        material's Bump Map Correction (on by default), soften the rest with
        a GGX shadowing term (Conty Estevez et al.)."""
        if self.version < 400:
            return "MP_NORMAL_INPUT"
        cycles = getattr(self.material, "cycles", None)
        if getattr(cycles, "use_bump_map_correction", True):
            return "MP_NORMAL_INPUT_V4"
        return "MP_NORMAL_INPUT_V4_UNCORRECTED"

    def _displacement_bound(self, displaces):
        if not displaces:
            return 0.0
        if self.user_bound > 0.0:
            return self.user_bound
        # The nodes' bounds add up: a tree adding two displacements moves no
        # further than both together.
        bounds = self.displacement_bounds
        if bounds and all(b is not None for b in bounds):
            return sum(bounds)
        self.warnings.append(f"material '{self.material.name}': its displacement bound could not be derived from "
                             "the node tree; 1 unit is assumed. Set Material > Micropoly > Displacement Bound if "
                             "displaced geometry is clipped")
        return 1.0


# Principled inputs the constant material path (export_materials and
# DeviceMaterial) has no room for: when unlinked at these values they add
# nothing, otherwise the material needs a program.
_PRINCIPLED_NEUTRAL = {"Diffuse Roughness": 0.0, "Subsurface Weight": 0.0, "Subsurface": 0.0, "Transmission Weight": 0.0,
                       "Transmission": 0.0, "Coat Weight": 0.0, "Clearcoat": 0.0, "Sheen Weight": 0.0, "Sheen": 0.0,
                       "Anisotropic": 0.0, "Thin Film Thickness": 0.0}


def _displacement_node_bound(value, mid, scale, spread):
    """How far a displacement node moves the surface, from its inputs' value
    ranges (value: a height, or each component of a vector, `spread` sqrt(3)
    for the vector's length), or None when they are unknown."""
    (_, _, vr), (_, _, mr), (_, _, sr) = value, mid, scale
    if vr and mr and sr and mr[0] == mr[1] and sr[0] == sr[1]:
        return abs(sr[0]) * spread * max(abs(vr[1] - mr[0]), abs(vr[0] - mr[0]))
    return None


def _constant_shader(node):
    """Whether shader `node` renders as a constant material (no program)."""
    if node.type not in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "EMISSION"):
        return False
    if any(s.is_linked for s in node.inputs):
        return False
    if node.type == "BSDF_DIFFUSE":
        return float(node.inputs["Roughness"].default_value) == 0.0
    if node.type == "BSDF_PRINCIPLED":
        for name, neutral in _PRINCIPLED_NEUTRAL.items():
            socket = node.inputs.get(name)
            if socket is not None and float(socket.default_value) != neutral:
                return False
        tint = node.inputs.get("Specular Tint")
        if blender_version() >= 400:
            # 4.x: a white tint, and the IOR the constant path assumes.
            if any(float(x) != 1.0 for x in list(tint.default_value)[:3]):
                return False
            if abs(float(node.inputs["IOR"].default_value) - 1.5) > 1e-6:
                return False
        elif float(tint.default_value) != 0.0:
            return False
    return True


def linked_from(socket):
    """(node, output socket) linked into `socket` past reroutes and muted
    links, or (None, None)."""
    link = next((l for l in socket.links if getattr(l, "is_valid", True) and not getattr(l, "is_muted", False)),
                None)
    if link is None:
        return None, None
    node, out = link.from_node, link.from_socket
    while node is not None and node.type == "REROUTE":
        inner = [l for l in node.inputs[0].links if not getattr(l, "is_muted", False)]
        if not inner:
            return None, None
        node, out = inner[0].from_node, inner[0].from_socket
    return node, out


def active_output(material):
    """The Material Output node a render uses (for all engines or Cycles), or None."""
    if not material.use_nodes or material.node_tree is None:
        return None
    outputs = [n for n in material.node_tree.nodes
               if n.type == "OUTPUT_MATERIAL" and getattr(n, "target", "ALL") in ("ALL", "CYCLES")]
    active = [n for n in outputs if n.is_active_output] or outputs
    return active[0] if active else None


def compile_material(material, warnings, resources=None):
    """CompiledMaterial for a Blender material, or None if it needs no program.
    `resources` gives UV layer and image indices (NoResources for the interface)."""
    settings = getattr(material, "micropoly", None)
    user_bound = float(getattr(settings, "displacement_bound", 0.0)) if settings is not None else 0.0
    return NodeCompiler(material, warnings, user_bound, resources).compile()
