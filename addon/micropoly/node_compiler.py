# SPDX-License-Identifier: GPL-3.0-or-later
"""Material node trees -> OpenCL C material programs.

A material's Surface shader inputs (Principled BSDF, Diffuse BSDF, Emission)
and its Displacement output are translated into two device functions,
mp_node_surface and mp_node_displacement (the contract is in
kernels/materials/material_program.cl; the node functions they call are in
kernels/materials/mp_node_lib.h and kernels/textures/). Every output socket
that is used becomes one local variable, computed once. The compiler walks
the tree and adds closures for shader nodes; every other node is compiled by
the function its family registers (node_registry.py). An unsupported node
gives one warning naming the material and the node, and its outputs take
their default values, so a render never fails on a node it cannot run."""

import bpy

from . import node_registry
from .node_kinds import FLOAT, VEC, finite, literal, vector_literal

# Closures a shading point holds (MP_MAX_CLOSURES, kernels/closures/mp_closures.h).
MAX_CLOSURES = 10


def blender_version():
    major, minor = bpy.app.version[:2]
    return major * 100 + minor


def _socket_kind(socket):
    return FLOAT if socket.type in ("VALUE", "INT", "BOOLEAN") else VEC


class CompiledMaterial:
    def __init__(self, source, displaces, shades, displacement_bound, displacement_world=False, alpha=False,
                 params=(), alpha_cut=False):
        self.source = source
        # The node values the program reads (MP_PARAM in its source): trees
        # that differ only in values share one source, so one program.
        self.params = list(params)
        self.displaces = displaces
        self.shades = shades
        self.alpha = alpha  # the program computes the surface's alpha (which shadow views read too)
        # ... and that alpha is a hard cut written as its edge's distance
        # (mp_alpha_cut): samples keep the surface where it exceeds one half.
        self.alpha_cut = alpha_cut
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

    def hair_info_layers(self):
        return -1, -1

    def layer_count(self):
        return 1

    def object_attribute(self, name, kind):
        return -1

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
        self.neighbours_of_neighbours = False  # a filtered image inside a Bump's height
        self.heights = 0           # height functions (Bump) being compiled, innermost last
        self.uses_thin_film = False
        self.uses_hair = False
        self.uses_subsurface_walk = False
        self.displacement_world = False
        self.displacement_bounds = []
        self.groups = []           # the Group nodes whose trees are being compiled, outermost first
        self.world = False         # compiling a world (baked into a map) rather than a material
        self.transparent = False   # the surface has Transparent closures (its alpha can be below 1)
        self.alpha_cuts = 0        # Principled Alphas that are hard cuts (Math Greater / Less Than)
        self.alpha_fractional = False  # transparency other than such cuts
        self.closures = 0          # closures the surface adds at most (MP_MAX_CLOSURES per vertex)
        self.params = []           # node values the program reads (MP_PARAM); not compiled in

    # ---- node values ----------------------------------------------------------
    # An artist's numbers (socket values, Value and RGB nodes, ramp stops, an
    # object's placement) are read from the material's parameters rather than
    # written into the source: a dragged slider or an animated value then
    # re-uploads numbers and rebuilds no program.
    def param(self, x):
        self.params.append(finite(x))
        return f"MP_PARAM({len(self.params) - 1})"

    def _params(self, v, n):
        """n values from v (padded with 0) as MP_PARAMn."""
        self.params.extend(finite(c) for c in (list(v) + [0.0] * n)[:n])
        return f"MP_PARAM{n}({len(self.params) - n})"

    def param3(self, v):
        return self._params(v, 3)

    def param4(self, v):
        return self._params(v, 4)

    def param_table(self, values):
        """A table of values (a curve's samples) as a pointer to the first."""
        self.params.extend(finite(c) for c in values)
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
                        self.fn.values[k] = (vector_literal(seq), VEC, None)
                    except TypeError:
                        self.fn.values[k] = (literal(dv), FLOAT, (float(dv), float(dv)))
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
        return self.uv_at(name)("g")

    def uv_at(self, name=""):
        """The same, for any globals: a function of their name."""
        layer = self.resources.uv_layer(name)
        return lambda g: f"{g}->uv[{layer}]"

    def with_footprint(self, node, key, default):
        """Input `key` of `node` as a float3 (`default(g)`, an expression of
        globals g, where it is not linked) and its change over one
        micropolygon along each axis of the grid: (value, d/dx, d/dy), the
        footprint an image lookup filters over (mp_tex_image_area)."""
        self.uses_neighbours = True
        if self.heights:
            self.neighbours_of_neighbours = True
        socket = node.inputs[key]
        if socket.is_linked:
            value = self.input(node, key, VEC)[0]
            fn = self.height_function(node, key, VEC)
            at = lambda g: f"{fn}({g})"
        else:
            value, at = default("g"), default
        dx = self.fn.temp(VEC, f"MP_FOOTPRINT(g, {at('g->dx')}, {value})")[0]
        dy = self.fn.temp(VEC, f"MP_FOOTPRINT(g, {at('g->dy')}, {value})")[0]
        return value, dx, dy

    def by_id(self, node, identifier, kind):
        for i, s in enumerate(node.inputs):
            if s.identifier == identifier:
                return self.input(node, i, kind)
        raise KeyError(identifier)

    # ---- nodes ----------------------------------------------------------------
    def emit(self, node):
        """The node's outputs, by the function its family registers for its
        type (node_registry.py); a group opens into its own tree."""
        if node.type == "GROUP":
            return self.emit_group(node)
        emit = node_registry.emitter(node.type)
        if emit is None:
            self.warn(node, "is not supported; its outputs take their default values")
            return {}
        return emit(self, node)

    def height_function(self, node, key, kind=FLOAT):
        """A helper function evaluating input `key` of `node` for any
        globals: a value differenced across the micropolygon (FLOAT: a
        Bump's height, an alpha cut's sides), or an image's coordinates
        (VEC)."""
        outer = self.fn
        name = f"mp_height_{len(self.helpers)}" if kind == FLOAT else f"mp_coordinates_{len(self.helpers)}"
        self.helpers.append(None)  # reserve the slot: nested heights get later ones
        slot = len(self.helpers) - 1
        ctype = "float" if kind == FLOAT else "float3"
        self.heights += kind == FLOAT
        try:
            text = self._function(f"{ctype} {name}(const MpNodeGlobals* g)",
                                  lambda: f"  return {self.input(node, key, kind)[0]};\n")
        finally:
            self.heights -= kind == FLOAT
        self.helpers[slot] = text
        self.fn = outer
        return name

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
        includes = "#define MP_NODE_USES_UV_LAYERS 1\n"  # the world reads none
        includes += "".join(f'#include "textures/{h}"\n' for h in sorted(self.headers))
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
        self.heights += bump_only  # evaluated at the neighbours too (bump_line)
        disp_src = self._function("float3 mp_node_displacement(const MpNodeGlobals* g)",
                                  lambda: "  return " + self.input(out, "Displacement", VEC)[0] + ";\n"
                                  if displaces or bump_only else "  return (float3)(0.0f);\n")
        self.heights -= bump_only
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
        # Only the UV layers taken so far (every one this program reads).
        includes = f"#define MP_NODE_USES_UV_LAYERS {max(1, self.resources.layer_count())}\n" + includes
        if self.uses_neighbours:
            includes = "#define MP_NODE_USES_NEIGHBOURS 1\n" + includes
        if self.neighbours_of_neighbours:
            includes = "#define MP_NODE_NEIGHBOURS_OF_NEIGHBOURS 1\n" + includes
        if self.uses_thin_film:
            # Ahead of the kernel headers (program_cache.cpp hoists it).
            includes = "#define MP_NODE_USES_THIN_FILM 1\n" + includes
        if self.uses_hair:
            includes = "#define MP_NODE_USES_HAIR 1\n" + includes
        if self.uses_subsurface_walk:
            includes = "#define MP_NODE_USES_SUBSURFACE_WALK 1\n" + includes
        source = includes + "".join(self.helpers) + disp_src + surf_src
        return CompiledMaterial(source, displaces, shades, bound, displaces and self.displacement_world,
                                alpha=self.transparent, params=self.params,
                                alpha_cut=self.transparent and self.alpha_cuts > 0 and not self.alpha_fractional)

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

    # A Math node's comparisons, as the side of its edge: a > b is a - b > 0.
    _CUTS = {"GREATER_THAN": "({0}) - ({1})", "LESS_THAN": "({1}) - ({0})"}

    @staticmethod
    def _clear_transparent(socket):
        """Whether a shader socket is fed straight by an unmuted Transparent
        BSDF of white, unlinked colour."""
        node, _ = linked_from(socket)
        if node is None or node.type != "BSDF_TRANSPARENT" or node.mute or node.inputs["Color"].is_linked:
            return False
        return all(abs(float(v) - 1.0) < 1e-6 for v in node.inputs["Color"].default_value[:3])

    def _alpha_cut(self, socket):
        """An Alpha linked straight from a Math Greater Than or Less Than (a
        hard cut, as leaves and fences are made) as the cut's side written
        with its edge's distance (mp_alpha_cut: linear across a micropolygon,
        one half on the edge), so the sampler can place the edge within
        the micropolygon; None for any other alpha."""
        node, _ = linked_from(socket)
        if node is None or node.type != "MATH" or node.mute or node.operation not in self._CUTS:
            return None
        self.uses_neighbours = True
        self.alpha_cuts += 1
        a, b = (self.height_function(node, k) for k in (0, 1))
        side = self._CUTS[node.operation]
        here = self.fn.temp(FLOAT, side.format(f"{a}(g)", f"{b}(g)"))[0]
        dx = self.fn.temp(FLOAT, f"MP_STEP_CHANGE(g, {side.format(f'{a}(g->dx)', f'{b}(g->dx)')}, {here})")[0]
        dy = self.fn.temp(FLOAT, f"MP_STEP_CHANGE(g, {side.format(f'{a}(g->dy)', f'{b}(g->dy)')}, {here})")[0]
        return self.fn.temp(FLOAT, f"mp_alpha_cut({here}, {dx}, {dy})")[0]

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
            # A clear Transparent BSDF mixed in by a comparison is a hard
            # alpha cut, as Principled Alpha fed by one is (older leaf and
            # fence materials are made this way).
            clear = [self._clear_transparent(node.inputs[k]) for k in (1, 2)]
            cut = self._alpha_cut(node.inputs[0]) if node.inputs[0].is_linked and clear[0] != clear[1] else None
            fac = cut or self.fn.temp(FLOAT, f"mp_nl_clamp01({self.input(node, 0, FLOAT)[0]})")[0]
            for k, w in ((1, f"(1.0f - {fac})"), (2, fac)):
                if cut is not None and clear[k - 1]:
                    self.transparent = True
                    self.fn.lines.append(f"  mp_add_transparent(s, {self._weighted(weight, w)});")
                else:
                    self.shader_input(node, k, self._weighted(weight, w))
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
            self.alpha_fractional = True
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
        elif t == "BSDF_HAIR_PRINCIPLED":
            self.emit_principled_hair(node, weight, slot)
        elif t == "BSDF_HAIR":
            # Cycles' Hair BSDF: one component, along the curve (or a
            # Tangent input), with the node's offset.
            self.uses_hair = True
            transmission = 1 if getattr(node, "component", "Reflection") == "Transmission" else 0
            tangent = self._tangent(node) if node.inputs["Tangent"].is_linked else "g->fibre"
            add(f"  mp_add_hair(s, {weight} * {color}, {slot}, {transmission}, {self._f(node, 'Offset')}, "
                f"{self._f(node, 'RoughnessU')}, {self._f(node, 'RoughnessV')}, {tangent}, g->fibre_radius);")
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
            # Anything else (volumes, ray portals, shaders of newer
            # Blender): a diffuse of its Color input, and a warning.
            self.warn(node, "is not supported; it is shaded as a Diffuse BSDF of its color")
            add(f"  mp_add_diffuse(s, {weight} * {color}, {slot}, 0.0f);")

    def emit_principled_hair(self, node, weight, slot):
        """Principled Hair BSDF as Chiang et al.'s model (kernels/closures/mp_hair.h),
        in each of its colour parametrisations. An unlinked Random is the
        strand's own (Hair Info's, as Cycles takes it); 4.x's Huang model is
        shaded as Chiang's with a warning."""
        self.uses_hair = True
        f, c = self._f, self._c
        if getattr(node, "model", "CHIANG") == "HUANG":
            self.warn(node, "the Huang model is shaded as Chiang's (its Reflection, Transmission, Secondary "
                            "Reflection and Aspect Ratio are not read)")
        random = f(node, "Random") if node.inputs["Random"].is_linked else "0.0f"
        if not node.inputs["Random"].is_linked and not (
                self._unlinked_zero(node, "Random Roughness") and self._unlinked_zero(node, "Random Color")):
            _, kb = self.resources.hair_info_layers()
            random = f"g->uv[{kb}].x" if kb >= 0 else "0.0f"
        var = f"hr{self.fn.counter}"
        self.fn.counter += 1
        add = self.fn.lines.append
        add(f"  float {var}_k = 1.0f + 2.0f * ({random} - 0.5f) * {f(node, 'Random Roughness')};")
        add(f"  float {var}_m = {f(node, 'Roughness')} * {var}_k, {var}_n = {f(node, 'Radial Roughness')} * {var}_k;")
        mode = getattr(node, "parametrization", "COLOR")
        if mode == "ABSORPTION":
            sigma = c(node, "Absorption Coefficient")
        elif mode == "MELANIN":
            melanin = (f"{f(node, 'Melanin')} * (1.0f + 2.0f * ({random} - 0.5f) * "
                       f"mp_nl_clamp01({f(node, 'Random Color')}))")
            sigma = f"mp_hair_sigma_from_melanin({melanin}, {f(node, 'Melanin Redness')}, {c(node, 'Tint')}, {var}_n)"
        else:
            sigma = f"mp_hair_sigma_from_colour({c(node, 'Color')}, {var}_n)"
        add(f"  mp_add_principled_hair(s, {weight}, {slot}, {sigma}, {var}_m, {var}_n, {f(node, 'Coat')}, "
            f"{f(node, 'IOR')}, {f(node, 'Offset')}, g->fibre, g->fibre_radius);")

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
        see_through = alpha is not None and (alpha.is_linked or float(alpha.default_value) < 1.0)
        cut = self._alpha_cut(alpha) if see_through and alpha.is_linked else None
        if see_through:
            self.transparent = True
            self.alpha_fractional = self.alpha_fractional or cut is None
        self._note_thin_film(node)
        fields = {
            "base_color": c(node, "Base Color"), "metallic": f(node, "Metallic"), "roughness": f(node, "Roughness"),
            "ior": f(node, "IOR", default="1.45f"), "alpha": cut or f(node, "Alpha", default="1.0f"),
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
