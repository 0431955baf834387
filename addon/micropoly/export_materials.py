# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender materials -> native materials.

The node connected to the active Material Output's Surface socket decides
the constant material: Principled BSDF (its Alpha as opacity) and Diffuse
BSDF give their constant inputs, an Emission shader gives emission; other
shader trees are material programs (node_compiler), whose closures replace
the constant material's shading; a material without a Surface link uses its
viewport color, metallic and roughness.

Materials Cycles builds itself follow Cycles (docs/blender-conventions.md,
"Missing materials"): a material whose nodes are off is a Diffuse BSDF of
its viewport colour, and an object or face without a material gets Cycles'
default surface."""

from . import export_images, node_compiler

# Material programs see at most this many UV maps (MP_MAX_UV_LAYERS).
MAX_UV_LAYERS = 8


def _input(node, *names, default=None):
    for name in names:
        socket = node.inputs.get(name)
        if socket is not None:
            return socket.default_value
    return default


def _surface_node(material):
    out = node_compiler.active_output(material)
    return node_compiler.linked_from(out.inputs["Surface"])[0] if out is not None else None


def _diffuse(params, color):
    """A Diffuse BSDF (Lambert: roughness 0 in Cycles) of `color`."""
    params.update(color=list(color)[:3], specular=0.0, roughness=1.0)
    return params


def default_surface_parameters():
    """Cycles' default surface, for objects and faces without a material:
    a Diffuse BSDF of 0.8 grey before Blender 5.0, a Principled BSDF with
    its default inputs from 5.0 on (ShaderManager::add_default)."""
    params = dict(model="principled", color=[0.8, 0.8, 0.8], metallic=0.0, roughness=0.5, specular=0.5,
                  emission=[0.0, 0.0, 0.0])
    if node_compiler.blender_version() >= 500:
        params.update(layered=True)
        return params
    return _diffuse(params, (0.8, 0.8, 0.8))


def material_parameters(material):
    """dict of add_material keyword arguments for a Blender material."""
    if material is None:
        return default_surface_parameters()
    params = dict(model="principled", color=[0.8, 0.8, 0.8], metallic=0.0, roughness=0.5, specular=0.5,
                  emission=[0.0, 0.0, 0.0])
    if not getattr(material, "use_nodes", True) or material.node_tree is None:
        # Cycles' sync: without nodes, a Diffuse BSDF of the viewport colour
        # (its metallic and roughness are for the viewport only).
        return _diffuse(params, material.diffuse_color)
    node = _surface_node(material)
    if node is None:
        params.update(color=list(material.diffuse_color)[:3], metallic=float(material.metallic),
                      roughness=float(material.roughness))
    elif node.type == "BSDF_PRINCIPLED":
        strength = float(_input(node, "Emission Strength", default=1.0))
        emission = _input(node, "Emission Color", "Emission", default=(0, 0, 0, 1))
        alpha = min(max(float(_input(node, "Alpha", default=1.0)), 0.0), 1.0)
        params.update(color=list(_input(node, "Base Color"))[:3], metallic=float(_input(node, "Metallic")),
                      roughness=float(_input(node, "Roughness")),
                      specular=float(_input(node, "Specular IOR Level", "Specular", default=0.5)),
                      emission=[c * strength for c in list(emission)[:3]], opacity=[alpha] * 3,
                      layered=node_compiler.blender_version() >= 400,
                      retro_diffuse=node_compiler.blender_version() < 400,
                      multiscatter=getattr(node, "distribution", "GGX") == "MULTI_GGX")
    elif node.type == "BSDF_DIFFUSE":
        _diffuse(params, _input(node, "Color"))
    elif node.type == "EMISSION":
        strength = float(_input(node, "Strength", default=1.0))
        params.update(color=[0.0, 0.0, 0.0], specular=0.0,
                      emission=[c * strength for c in list(_input(node, "Color"))[:3]])
    else:
        params.update(color=list(material.diffuse_color)[:3], metallic=float(material.metallic),
                      roughness=float(material.roughness))
    return params


class MaterialTable:
    """One native material per Blender material; index 0 is Blender's default grey.
    Node trees that need per-point evaluation (textures, displacement) become
    material programs; identical trees share one."""

    def __init__(self, native_scene, warnings=None):
        self.native = native_scene
        self.index = {}
        self.programs = {}  # generated source -> program index
        self.warnings = warnings if warnings is not None else []
        # UV maps the programs read, by name ("" = each mesh's active render
        # UV map); meshes export these layers in this order.
        self.uv_names = []
        # Attribute nodes of type Object or Instancer: (name, instancer) per
        # slot (export_attributes.py).
        self.object_attributes = []
        # Whether the scene has point clouds: only then does an Attribute
        # node of type Geometry take a slot for their points' values.
        self.point_clouds = False
        self.images = export_images.ImageTable(native_scene)
        native_scene.add_material(name="default", **material_parameters(None))

    # ---- what node programs ask for (node_compiler.NoResources) ----
    def uv_layer(self, name):
        if name not in self.uv_names:
            if len(self.uv_names) == MAX_UV_LAYERS:
                self.warnings.append(f"more than {MAX_UV_LAYERS} UV maps are used; '{name}' reads the first")
                return 0
            self.uv_names.append(name)
        return self.uv_names.index(name)

    def tangent_layers(self, name):
        """Two layers holding the MikkTSpace tangents of UV map `name`
        (export_mesh computes them), or (-1, -1) when the layers run out."""
        if len(self.uv_names) + sum(("tangent", name, k) not in self.uv_names for k in (0, 1)) > MAX_UV_LAYERS:
            self.warnings.append(f"more than {MAX_UV_LAYERS} UV layers with tangents are used; "
                                 f"'{name or 'the active UV map'}' gets none: Normal Map takes its tangents "
                                 "from the UVs there, Tangent and Vector Displacement have none")
            return -1, -1
        return tuple(self.uv_layer(("tangent", name, k)) for k in (0, 1))

    def attribute_layers(self, name):
        """Two layers holding attribute `name`'s RGBA per face corner ("":
        the active render color attribute; export_mesh), or (-1, -1) when
        the layers run out."""
        if len(self.uv_names) + sum(("attribute", name, k) not in self.uv_names for k in (0, 1)) > MAX_UV_LAYERS:
            self.warnings.append(f"more than {MAX_UV_LAYERS} UV layers and attributes are used; attribute "
                                 f"'{name or 'the active color attribute'}' reads zero")
            return -1, -1
        return tuple(self.uv_layer(("attribute", name, k)) for k in (0, 1))

    def layer_count(self):
        """How many UV layers the materials compiled so far read."""
        return len(self.uv_names)

    def hair_info_layers(self):
        """Two layers holding a curve's Hair Info values per point:
        (intercept, length) and (random, thickness) (export_curves); zero on
        meshes. (-1, -1) when the layers run out."""
        if len(self.uv_names) + sum(("hair", k) not in self.uv_names for k in (0, 1)) > MAX_UV_LAYERS:
            self.warnings.append(f"more than {MAX_UV_LAYERS} UV layers and attributes are used; Hair Info "
                                 "reads zero")
            return -1, -1
        return tuple(self.uv_layer(("hair", k)) for k in (0, 1))

    def object_attribute(self, name, kind):
        """The slot of value `name` of `kind` that every object carries
        (export_attributes.py): Attribute nodes of type Object ("OBJECT") or
        Instancer ("INSTANCER"), a point cloud's attribute ("POINT") or
        Point Info ("POINT_INFO")."""
        if kind in ("POINT", "POINT_INFO") and not self.point_clouds:
            return -1
        key = (name, kind)
        if key not in self.object_attributes:
            self.object_attributes.append(key)
        return self.object_attributes.index(key)

    def image(self, image, warn):
        return self.images.get(image, warn)

    def array_image(self, key, pixels):
        return self.images.array(key, pixels)

    def get(self, material):
        if material is None:
            return 0
        key = material.name_full if hasattr(material, "name_full") else material.name
        if key not in self.index:
            params = material_parameters(material)
            compiled = node_compiler.compile_material(material, self.warnings, self)
            if compiled is not None:
                program = self.programs.get(compiled.source)
                if program is None:
                    program = self.native.add_material_program(key, compiled.source)
                    self.programs[compiled.source] = program
                params.update(program=program, program_params=compiled.params, program_displaces=compiled.displaces,
                              program_shades=compiled.shades, displacement_bound=compiled.displacement_bound,
                              displacement_bound_world=compiled.displacement_world, program_alpha=compiled.alpha,
                              program_alpha_cut=compiled.alpha_cut)
            self.native.add_material(name=key, **params)
            self.index[key] = self.native.material_count - 1
        return self.index[key]
