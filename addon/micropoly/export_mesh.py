# SPDX-License-Identifier: GPL-3.0-or-later
"""Mesh objects -> native meshes, through foreach_get and numpy only.

An object whose last render-enabled modifier is a Catmull-Clark Subdivision
Surface is rendered as the exact limit surface of the mesh under that
modifier; its boundary setting and (when enabled) the mesh's edge and vertex
creases are passed on. Everything else renders as flat polygons."""

import numpy as np

from . import export_attributes

# Blender's crease values in [0, 1] become OpenSubdiv sharpness as Blender's
# own OpenSubdiv integration maps them (docs/blender.md).
CREASE_SHARPNESS_SCALE = 10.0


def crease_to_sharpness(crease):
    return crease * crease * CREASE_SHARPNESS_SCALE


def _float_attribute(mesh, name, legacy_collection, legacy_property, size):
    """A float attribute by its 4.x name, else through the 3.x property."""
    attributes = getattr(mesh, "attributes", None)
    attr = attributes.get(name) if attributes is not None else None
    out = np.zeros(size, dtype=np.float32)
    if attr is not None and attr.data_type == "FLOAT" and len(attr.data) == size:
        attr.data.foreach_get("value", out)
        return out
    collection = legacy_collection(mesh)
    if collection is not None and size:
        try:
            collection.foreach_get(legacy_property, out)
            return out
        except (AttributeError, TypeError, RuntimeError):
            pass
    return out


def _vertex_crease_layer(mesh):
    layers = getattr(mesh, "vertex_creases", None)  # Blender 3.x
    return layers[0].data if layers else None


def subdivision_modifier(obj):
    """(modifier, is_only_modifier) when the object ends in a Catmull-Clark
    Subdivision Surface modifier enabled for rendering, else (None, False)."""
    original = obj.original
    mods = [m for m in original.modifiers if m.show_render]
    if mods and mods[-1].type == "SUBSURF" and mods[-1].subdivision_type == "CATMULL_CLARK":
        return mods[-1], len(mods) == 1
    return None, False


def _shape_keys(obj, depsgraph):
    """The cage's relative shape keys with the values they have at the
    depsgraph's time (its evaluated Key), or None."""
    keys = obj.original.data.shape_keys
    if keys is None or not keys.use_relative or len(keys.key_blocks) < 2:
        return None
    return keys.evaluated_get(depsgraph) if depsgraph is not None else keys


def _key_co(block):
    co = np.empty(len(block.data) * 3, dtype=np.float32)
    block.data.foreach_get("co", co)
    return co.reshape(-1, 3)


def cage_points(obj, depsgraph=None, points=None):
    """The points of the cage under a Subdivision Surface as they are at the
    depsgraph's time: the mesh's vertices with its relative shape keys mixed
    in, Basis + sum of value x (key - its relative key), for keys not muted
    (a key's vertex group is not applied). `points`: the vertices, if read."""
    mesh = obj.original.data
    if points is None:
        points = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", points)
        points = points.reshape(-1, 3)
    keys = _shape_keys(obj, depsgraph)
    if keys is None:
        return points
    out = points.copy()
    reference = keys.reference_key.name
    for block in keys.key_blocks:
        if block.name == reference or block.mute or block.value == 0.0:
            continue
        out += block.value * (_key_co(block) - _key_co(block.relative_key))
    return out


class MeshCache:
    """Arrays per mesh, so instances of one mesh export it once, and the
    viewport re-reads only meshes whose geometry changed. Keys: ("cage", mesh
    name) for the mesh under a Subdivision Surface, ("eval", object name) for
    an object's evaluated mesh. The arrays depend on the UV maps that node
    programs read, so a change of those starts a new cache."""

    def __init__(self):
        self.arrays = {}
        self.uv_names = None

    def for_uv_names(self, uv_names):
        if self.uv_names != list(uv_names):
            self.arrays.clear()
            self.uv_names = list(uv_names)

    def forget(self, id_data):
        """Drops what was read from an object or mesh whose geometry changed."""
        names = {id_data.name_full}
        data = getattr(id_data, "data", None)
        if data is not None:
            names.add(data.name_full)
        for key in [k for k in self.arrays if k[1] in names]:
            del self.arrays[key]


def _uv_layer(mesh, name):
    """The UV map of that name; "" names the active render UV map."""
    layers = mesh.uv_layers
    if name:
        return layers.get(name)
    return next((l for l in layers if l.active_render), None) or layers.active


def _tangents(mesh, layer, n_loops, counts):
    """(n_loops, 4): MikkTSpace tangent xyz and bitangent sign per face corner
    for UV map `layer`, as Blender computes them for normal maps (and Cycles
    too); all zeros for a mesh with a face of more than four sides, which
    Blender computes none for: the Normal Map node then takes its tangents
    from the UVs."""
    out = np.zeros((n_loops, 4), dtype=np.float32)
    if counts.size and counts.max() > 4:
        return out  # Blender refuses (with an error report) rather than skip those faces
    try:
        mesh.calc_tangents(uvmap=layer.name)
    except RuntimeError:
        return out
    try:
        flat = np.empty(n_loops * 3, dtype=np.float32)
        mesh.loops.foreach_get("tangent", flat)
        out[:, :3] = flat.reshape(-1, 3)
        sign = np.empty(n_loops, dtype=np.float32)
        mesh.loops.foreach_get("bitangent_sign", sign)
        out[:, 3] = sign
    finally:
        mesh.free_tangents()
    return out


def _attribute_corners(mesh, name, n_loops, counts):
    """(n_loops, 4) per face corner (`counts`: corners per face): attribute `name` ("" the active render
    color attribute) as RGBA (a float as (x, x, x, 1), a vector as (x, y, z, 1)),
    from the point, corner or face domain; None if the mesh lacks it."""
    attrs = getattr(mesh, "attributes", None)
    if attrs is None:
        return None
    if not name:
        colors = getattr(mesh, "color_attributes", None)
        if colors is None or not len(colors):
            return None
        index = getattr(colors, "render_color_index", getattr(colors, "active_color_index", 0))
        layer = colors[index] if 0 <= index < len(colors) else colors[0]
    else:
        layer = attrs.get(name)
    if layer is None or layer.domain not in ("POINT", "CORNER", "FACE"):
        return None
    rgba = export_attributes.attribute_rgba(layer)
    if rgba is None:
        return None
    if layer.domain == "CORNER":
        return rgba
    if layer.domain == "POINT":
        vertex = np.empty(n_loops, dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", vertex)
        return rgba[vertex]
    return np.repeat(rgba, counts, axis=0)


def _uv_layers(mesh, names, n_loops, counts):
    """(len(names), n_loops, 2) per face corner: a name is a UV map ("" the
    active render one), ("tangent", map, k) for half k of that map's
    tangents (xy, then z and the bitangent sign), ("attribute", name, k)
    for half k of an attribute's RGBA (_attribute_corners), or ("hair", k)
    for Hair Info's values (zero on meshes). A map or
    attribute the mesh lacks reads zero, as in Cycles."""
    out = np.zeros((len(names), n_loops, 2), dtype=np.float32)
    tangents = {}
    attributes = {}
    for k, name in enumerate(names):
        if isinstance(name, tuple) and name[0] == "hair":
            continue  # Hair Info reads zero on meshes, as in Cycles
        if isinstance(name, tuple) and name[0] == "attribute":
            if name[1] not in attributes:
                attributes[name[1]] = _attribute_corners(mesh, name[1], n_loops, counts)
            if attributes[name[1]] is not None:
                out[k] = attributes[name[1]][:, 2 * name[2]:2 * name[2] + 2]
            continue
        if isinstance(name, tuple):
            layer = _uv_layer(mesh, name[1])
            if layer is None:
                continue
            if name[1] not in tangents:
                tangents[name[1]] = _tangents(mesh, layer, n_loops, counts)
            out[k] = tangents[name[1]][:, 2 * name[2]:2 * name[2] + 2]
            continue
        layer = _uv_layer(mesh, name)
        if layer is None:
            continue
        flat = np.empty(n_loops * 2, dtype=np.float32)
        if hasattr(layer, "uv"):  # Blender 3.5 and later
            layer.uv.foreach_get("vector", flat)
        else:
            layer.data.foreach_get("uv", flat)
        out[k] = flat.reshape(-1, 2)
    return out


def _corner_normals(mesh, n_polys, n_loops):
    """(n_loops, 3) shading normals per face corner when any face is shaded
    smooth (or the mesh has custom normals), else None (flat faces). They
    are Blender's own corner normals, so sharp edges, Auto Smooth and custom
    normals count as in Cycles."""
    smooth = np.zeros(n_polys, dtype=bool)
    if n_polys:
        mesh.polygons.foreach_get("use_smooth", smooth)
    if not smooth.any() and not getattr(mesh, "has_custom_normals", False):
        return None
    out = np.empty(n_loops * 3, dtype=np.float32)
    if hasattr(mesh, "corner_normals"):  # Blender 4.1 and later
        mesh.corner_normals.foreach_get("vector", out)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", out)
    return out.reshape(-1, 3)


def _mesh_arrays(mesh, with_creases, uv_names=(), smooth_normals=False):
    n_verts, n_polys, n_loops, n_edges = len(mesh.vertices), len(mesh.polygons), len(mesh.loops), len(mesh.edges)
    points = np.empty(n_verts * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", points)
    counts = np.empty(n_polys, dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", counts)
    indices = np.empty(n_loops, dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", indices)
    material_index = np.empty(n_polys, dtype=np.int32)
    mesh.polygons.foreach_get("material_index", material_index)
    arrays = dict(points=points.reshape(-1, 3), counts=counts, indices=indices, material_index=material_index)
    if uv_names:
        arrays["uv_layers"] = _uv_layers(mesh, uv_names, n_loops, counts)
    if smooth_normals:
        normals = _corner_normals(mesh, n_polys, n_loops)
        if normals is not None:
            arrays["corner_normals"] = normals
    if with_creases:
        edge_crease = _float_attribute(mesh, "crease_edge", lambda m: m.edges, "crease", n_edges)
        creased = np.nonzero(edge_crease > 0.0)[0]
        if creased.size:
            edges = np.empty(n_edges * 2, dtype=np.int32)
            mesh.edges.foreach_get("vertices", edges)
            arrays["crease_vertices"] = edges.reshape(-1, 2)[creased].reshape(-1)
            arrays["crease_sharpness"] = crease_to_sharpness(edge_crease[creased])
        vertex_crease = _float_attribute(mesh, "crease_vert", _vertex_crease_layer, "value", n_verts)
        cornered = np.nonzero(vertex_crease > 0.0)[0].astype(np.int32)
        if cornered.size:
            arrays["corner_vertices"] = cornered
            arrays["corner_sharpness"] = crease_to_sharpness(vertex_crease[cornered])
    return arrays


def ray_visibility(obj):
    """(seen by the camera, casts shadows): Object > Visibility > Ray
    Visibility, as Cycles reads it (visible_camera and visible_shadow since
    Blender 3.0)."""
    return bool(getattr(obj, "visible_camera", True)), bool(getattr(obj, "visible_shadow", True))


def _hash_string(name):
    """Cycles' string hash (util/hash.h): i = i * 37 + byte, 32-bit."""
    i = 0
    for c in name.encode("utf-8"):
        i = (i * 37 + c) & 0xFFFFFFFF
    return i


def hash_uint2(kx, ky):
    """Cycles' hash_uint2 of arrays of 32-bit words: Bob Jenkins' lookup3
    final mix of two words, element-wise (uint32)."""
    m = np.uint64(0xFFFFFFFF)
    kx = np.asarray(kx, dtype=np.int64).astype(np.uint64) & m
    ky = np.asarray(ky, dtype=np.int64).astype(np.uint64) & m

    def mix(x, y, k):  # x ^= y; x -= rot(y, k), without wrapping below zero
        rot = ((y << np.uint64(k)) | (y >> np.uint64(32 - k))) & m
        return ((x ^ y) + (m + np.uint64(1) - rot)) & m
    a = b = c = np.full(np.broadcast(kx, ky).shape, 0xDEADBEEF + (2 << 2) + 13, dtype=np.uint64)
    a, b = (a + kx) & m, (b + ky) & m
    c = mix(c, b, 14)
    a = mix(a, c, 11)
    b = mix(b, a, 25)
    c = mix(c, b, 16)
    a = mix(a, c, 4)
    b = mix(b, a, 14)
    c = mix(c, b, 24)
    return c.astype(np.uint32)


def name_random_id(name):
    """The random id Cycles gives an object of its own: the hash of its name."""
    return int(hash_uint2(_hash_string(name), 0))


def object_random(name, random_id=None):
    """Object Info's Random as Cycles gives it: an instance's random id, or
    for an object of its own the hash of its name, over 0xFFFFFFFF (float)."""
    rid = (random_id & 0xFFFFFFFF) if random_id is not None else name_random_id(name)
    return float(np.float32(rid) * np.float32(1.0 / 0xFFFFFFFF))


def random_from_ids(ids):
    """object_random of many random ids (an integer array) at once."""
    return (ids & 0xFFFFFFFF).astype(np.float32) * np.float32(1.0 / 0xFFFFFFFF)


def export_object(native_scene, materials, cache, obj, matrix, warnings, is_instance=False, depsgraph=None,
                  random_id=None):
    """Adds one mesh instance; returns False when it has no faces or nothing
    it would be seen in (neither the camera nor shadows). `depsgraph` gives
    the cage's shape keys their values at its time."""
    visible_camera, cast_shadows = ray_visibility(obj)
    if not visible_camera and not cast_shadows:
        return False
    subsurf, only = subdivision_modifier(obj)
    if subsurf is not None and not only:
        warnings.append(f"'{obj.name}' renders its subdivided mesh as polygons: Micropoly renders the exact "
                        "limit surface only when the Subdivision Surface modifier is the only modifier")
        subsurf = None
    cage = obj.original.data if subsurf is not None else None
    cache.for_uv_names(materials.uv_names)
    # Instances made by geometry nodes or particles may carry meshes of their
    # own under the instanced object's name: only real objects are cached.
    keys = _shape_keys(obj, depsgraph) if cage is not None else None
    key = ("cage", cage.name_full) if cage is not None else (("eval", obj.name_full) if not is_instance else None)
    if keys is not None:  # shape keys move the cage: their values are part of it
        key = key + tuple(block.value for block in keys.key_blocks)
    arrays = cache.arrays.get(key) if key else None
    if arrays is None:
        if cage is not None and obj.original.mode == "EDIT":
            obj.original.update_from_editmode()  # the cage as edited so far
        mesh = cage if cage is not None else obj.to_mesh()
        try:
            arrays = _mesh_arrays(mesh, with_creases=subsurf is not None and subsurf.use_creases,
                                  uv_names=materials.uv_names, smooth_normals=subsurf is None)
            if keys is not None:
                arrays["points"] = cage_points(obj, depsgraph, arrays["points"])
        finally:
            if cage is None:
                obj.to_mesh_clear()
        if key:
            cache.arrays[key] = arrays
    if arrays["counts"].size == 0:
        return False
    slots = [materials.get(slot.material) for slot in obj.material_slots] or [0]
    lut = np.array(slots, dtype=np.int32)
    face_materials = lut[np.clip(arrays["material_index"], 0, len(lut) - 1)]
    boundary = "edge_and_corner"
    if subsurf is not None and subsurf.boundary_smooth == "ALL":
        boundary = "edge_only"
    # Material > Settings > Backface Culling on every material makes the
    # object single-sided, as in EEVEE and the viewport.
    used = [slot.material for slot in obj.material_slots if slot.material is not None]
    double_sided = not used or not all(getattr(m, "use_backface_culling", False) for m in used)
    empty_i, empty_f = np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.float32)
    native_scene.add_mesh(
        obj.name, arrays["points"], arrays["counts"], arrays["indices"], subdivision=subsurf is not None,
        object_to_world=matrix, face_materials=face_materials,
        crease_vertices=arrays.get("crease_vertices", empty_i), crease_sharpness=arrays.get("crease_sharpness", empty_f),
        corner_vertices=arrays.get("corner_vertices", empty_i), corner_sharpness=arrays.get("corner_sharpness", empty_f),
        boundary=boundary, double_sided=double_sided, uv_layers=arrays.get("uv_layers", empty_f),
        corner_normals=arrays.get("corner_normals", empty_f), visible_camera=visible_camera,
        cast_shadows=cast_shadows, object_color=list(obj.color), pass_index=float(obj.pass_index),
        random=object_random(obj.name, random_id if is_instance else None),
        attributes=export_attributes.object_values(materials.object_attributes, obj),
        **_texture_space(obj.original.data))
    return True


def _texture_space(mesh):
    """Generated coordinates' texture space, as Blender keeps it on the mesh
    (the attribute names differ between Blender versions)."""
    for loc, size in (("texspace_location", "texspace_size"), ("texture_space_location", "texture_space_size")):
        if hasattr(mesh, loc):
            return dict(texspace_location=list(getattr(mesh, loc)), texspace_size=list(getattr(mesh, size)))
    return {}
