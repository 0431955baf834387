"""Cycles references kept with the tests.

Most Blender tests compare Micropoly's render with Cycles' render of the same
scene. Cycles at 64 to 512 samples is most of such a test's time, yet its
image changes only when the scene, the script that builds it or Blender
changes. So, as Blender's own render tests keep reference images, Cycles'
passes are stored once per Blender version, under

    tests/references/cycles/<Blender version>/<script>/<key>.npz

with the script, its SHA-256 and the Blender version that made them. The key
is a fingerprint of everything Cycles reads from the scene (render and Cycles
settings, objects, meshes, modifiers, materials and their node trees, lights,
cameras, the world, image pixels), the script's source and the render size.
A test reuses a stored reference only when all of these match; otherwise it
renders Cycles as before and says so. `scripts/build/cycles_references.sh`
renders them again (MICROPOLY_CYCLES_REFERENCES=update) when a scene changes.
"""

import hashlib
import inspect
import json
import os
import tempfile

import bpy
import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "references", "cycles"))
REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
MODE_VARIABLE = "MICROPOLY_CYCLES_REFERENCES"

# Properties that say nothing about the image, or change from run to run.
_SKIPPED = frozenset((
    "rna_type", "session_uid", "users", "tag", "is_evaluated", "original", "use_fake_user",
    "use_extra_user", "is_missing", "preview", "library", "library_weak_reference", "override_library",
    "is_dirty", "bindcode", "is_runtime_data", "is_editmode", "mode", "select", "hide_select",
    "is_embedded_data", "is_library_indirect", "asset_data", "id_type", "is_float", "has_data",
    "frame_duration", "packed_file", "packed_files", "pixels", "bound_box", "dimensions",
    "is_property_readonly", "hide_viewport", "show_expanded", "location_ui", "width", "height",
    "dimensions_ui", "select_head", "select_tail", "use_custom_color", "color_tag",
))
_TEMP = os.path.realpath(tempfile.gettempdir())


def _text(value):
    """A string as it bears on the image: paths into a temporary folder or
    this checkout lose the part that differs between runs and clones."""
    value = value.replace(REPO, "<repo>")  # first: a checkout may lie in the temporary folder
    if _TEMP in value or tempfile.gettempdir() in value:
        return "<temp>/" + os.path.basename(value)
    return value


def _plain(prop, value):
    if prop.type == "STRING":
        return _text(value)
    if prop.type == "ENUM" and isinstance(value, set):
        return sorted(value)
    if getattr(prop, "is_array", False) or getattr(prop, "array_length", 0) > 0:
        return np.asarray(value, dtype=np.float64).ravel().tolist()
    return value


def _walk(struct, depth, out, prefix=""):
    """Appends `name=value` lines for struct's RNA properties; pointers to
    IDs by name, other pointers and collections down to `depth` levels.
    Micropoly's own settings come last, where registering the add-on after
    Blender's own add-ons puts them: Blender lists an add-on's properties in
    the order add-ons registered them, and resetting the factory settings
    registers Blender's again while Micropoly's stay."""
    props = list(struct.bl_rna.properties)
    props.sort(key=lambda prop: prop.identifier == "micropoly")  # stable: all else keeps its order
    for prop in props:
        name = prop.identifier
        if name in _SKIPPED:
            continue
        try:
            value = getattr(struct, name)
        except (AttributeError, RuntimeError, TypeError):
            continue
        key = prefix + name
        if prop.type in ("BOOLEAN", "INT", "FLOAT", "STRING", "ENUM"):
            try:
                out.append(f"{key}={_plain(prop, value)!r}")
            except (TypeError, ValueError):
                continue
        elif prop.type == "POINTER":
            if value is None:
                out.append(f"{key}=None")
            elif isinstance(value, bpy.types.ID):
                out.append(f"{key}->{value.name}")
            elif depth > 0:
                _walk(value, depth - 1, out, key + ".")
        elif prop.type == "COLLECTION" and depth > 0:
            for i, item in enumerate(value):
                if isinstance(item, bpy.types.ID):
                    out.append(f"{key}[{i}]->{item.name}")
                else:
                    _walk(item, depth - 1, out, f"{key}[{i}].")


_WIDTHS = {"FLOAT": 1, "INT": 1, "BOOLEAN": 1, "INT8": 1, "FLOAT2": 2, "FLOAT_VECTOR": 3, "FLOAT_COLOR": 4,
           "BYTE_COLOR": 4}


def _attribute_values(attribute):
    """An attribute's values as (count, width) floats, or None for types
    that do not shade (strings)."""
    width = _WIDTHS.get(attribute.data_type)
    if width is None:
        return None
    field = "value" if width == 1 else ("color" if "COLOR" in attribute.data_type else "vector")
    dtype = {"BOOLEAN": bool, "INT": np.int32, "INT8": np.int32}.get(attribute.data_type, np.float32)
    values = np.zeros(len(attribute.data) * width, dtype=dtype)
    try:
        attribute.data.foreach_get(field, values)
    except (AttributeError, RuntimeError, TypeError):
        return None
    return values.astype(np.float64).reshape(-1, width)


def _mesh(mesh, out):
    """The mesh's digest, independent of the order of its faces, of each
    face's first corner and of its edges: Blender's primitives (the UV
    sphere) come out in a different face order from run to run."""
    out.append(f"mesh {mesh.name} v={len(mesh.vertices)} e={len(mesh.edges)} p={len(mesh.polygons)}")
    co = np.zeros(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    out.append("co " + hashlib.sha256(co.tobytes()).hexdigest())
    corner_vertex = np.zeros(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    start = np.zeros(len(mesh.polygons), dtype=np.int64)
    total = np.zeros(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_start", start)
    mesh.polygons.foreach_get("loop_total", total)
    face_columns = []
    for name in ("material_index", "use_smooth"):
        values = np.zeros(len(mesh.polygons), dtype=np.int32)
        mesh.polygons.foreach_get(name, values)
        face_columns.append(values.astype(np.float64)[:, None])
    corner_columns = [corner_vertex.astype(np.float64)[:, None]]
    for layer in mesh.uv_layers:
        uv = np.zeros(len(mesh.loops) * 2, dtype=np.float32)
        layer.data.foreach_get("uv", uv)
        corner_columns.append(uv.astype(np.float64).reshape(-1, 2))
    edge_vertices = np.zeros(len(mesh.edges) * 2, dtype=np.int64)
    mesh.edges.foreach_get("vertices", edge_vertices)
    edge_columns = [np.sort(edge_vertices.reshape(-1, 2), axis=1).astype(np.float64)]
    for attribute in sorted(mesh.attributes, key=lambda a: a.name):
        values = _attribute_values(attribute)
        if values is None or attribute.name.startswith("."):
            continue
        out.append(f"attribute {attribute.name} {attribute.domain} {attribute.data_type}")
        if attribute.domain == "POINT":
            out.append("  " + hashlib.sha256(values.tobytes()).hexdigest())
        elif attribute.domain == "FACE":
            face_columns.append(values)
        elif attribute.domain == "CORNER":
            corner_columns.append(values)
        elif attribute.domain == "EDGE":
            edge_columns.append(values)
    corners = np.concatenate(corner_columns, axis=1)
    faces = np.concatenate(face_columns, axis=1)
    for size in np.unique(total):
        chosen = np.nonzero(total == size)[0]
        index = start[chosen][:, None] + np.arange(size)[None, :]
        first = np.argmin(corner_vertex[index], axis=1)
        index = np.take_along_axis(index, (np.arange(size)[None, :] + first[:, None]) % size, axis=1)
        rows = np.concatenate([corners[index].reshape(len(chosen), -1), faces[chosen]], axis=1)
        rows = rows[np.lexsort(rows.T[::-1])]
        out.append(f"faces of {size} " + hashlib.sha256(rows.tobytes()).hexdigest())
    edges = np.concatenate(edge_columns, axis=1)
    edges = edges[np.lexsort(edges.T[::-1])] if len(edges) else edges
    out.append("edges " + hashlib.sha256(edges.tobytes()).hexdigest())
    out.extend(f"slot {m.name if m else None}" for m in mesh.materials)


def _node_tree(tree, out, seen):
    # By identity, not name: every material's and world's own tree is
    # called "Shader Nodetree".
    if tree is None or tree.as_pointer() in seen:
        return
    seen.add(tree.as_pointer())
    out.append(f"tree {tree.name}")
    for node in sorted(tree.nodes, key=lambda n: n.name):
        out.append(f"node {node.name} {node.bl_idname}")
        _walk(node, 3, out, "  ")
        for socket in list(node.inputs) + list(node.outputs):
            if hasattr(socket, "default_value"):
                value = socket.default_value
                try:
                    value = np.asarray(value, dtype=np.float64).ravel().tolist()
                except (TypeError, ValueError):
                    value = getattr(value, "name", value)
                out.append(f"  socket {socket.identifier} {socket.enabled} {value!r}")
        if getattr(node, "node_tree", None) is not None:
            _node_tree(node.node_tree, out, seen)
        image = getattr(node, "image", None)
        if image is not None:
            _image(image, out)
    for link in sorted(tree.links, key=lambda l: (l.to_node.name, l.to_socket.identifier)):
        out.append(f"link {link.from_node.name}.{link.from_socket.identifier} -> "
                   f"{link.to_node.name}.{link.to_socket.identifier} {link.is_muted}")


def _image(image, out):
    _walk(image, 1, out, f"image {image.name} ")
    w, h = image.size
    pixels = np.zeros(w * h * image.channels, dtype=np.float32)
    if len(pixels):
        image.pixels.foreach_get(pixels)
    out.append(f"image {image.name} {w}x{h} {hashlib.sha256(pixels.tobytes()).hexdigest()}")


def _material(material, out, seen):
    if material is None:
        out.append("material None")
        return
    _walk(material, 1, out, f"material {material.name} ")
    if material.use_nodes:
        _node_tree(material.node_tree, out, seen)


def fingerprint(scene):
    """Text describing everything in `scene` that Cycles' image depends on."""
    # Objects' world matrices are those of the last evaluation until the
    # depsgraph updates (the render would update it next).
    for layer in scene.view_layers:
        layer.update()
    out = [f"blender {bpy.app.version_string}", f"frame {scene.frame_current} {scene.frame_subframe}"]
    for name in ("render", "cycles", "view_settings", "display_settings"):
        _walk(getattr(scene, name), 3, out, name + ".")
    out.append(f"camera {scene.camera.name if scene.camera else None}")
    # Cycles' hair shape (3D Curves or Rounded Ribbons), where there is hair.
    hair = any(obj.type == "CURVES" or any(p.settings.type == "HAIR" for p in getattr(obj, "particle_systems", ()))
               for obj in scene.objects)
    if hair and hasattr(scene, "cycles_curves"):
        out.append(f"hair shape {scene.cycles_curves.shape}")
    for layer in scene.view_layers:
        _walk(layer, 1, out, f"view_layer {layer.name} ")
    seen = set()
    if scene.world is not None:
        _walk(scene.world, 1, out, "world ")
        if scene.world.use_nodes:
            _node_tree(scene.world.node_tree, out, seen)
    for obj in sorted(scene.objects, key=lambda o: o.name):
        _walk(obj, 2, out, f"object {obj.name} ")
        out.append("matrix " + repr(np.asarray(obj.matrix_world, dtype=np.float64).ravel().tolist()))
        for slot in obj.material_slots:
            out.append(f"material_slot {slot.link}")
            _material(slot.material, out, seen)
        data = obj.data
        if isinstance(data, bpy.types.Mesh):
            _mesh(data, out)
        elif data is not None:
            _walk(data, 2, out, f"data {data.name} ")
            if getattr(data, "use_nodes", False) and getattr(data, "node_tree", None) is not None:
                _node_tree(data.node_tree, out, seen)
    return "\n".join(out)


# Colour and normals at half precision (Cycles' noise is far above its
# 1/2048 steps) where half floats hold them; depth (the background's is
# 1e10) and bright colour (a sun's disc) at full.
_HALF_LIMIT = 60000.0


def _stored_type(key, values):
    if key == "depth" or not np.all(np.abs(values) < _HALF_LIMIT):
        return np.float32
    return np.float16


def as_stored(passes):
    """Cycles' passes at the precision they are stored with, so that a test
    sees the same values whether Cycles ran now or its reference was read."""
    return {k: (None if v is None else np.asarray(v, dtype=_stored_type(k, v)).astype(np.float32))
            for k, v in passes.items()}


def _calling_script():
    """The test script (tests/blender/test_*.py) that asked for a render."""
    for frame in inspect.stack():
        name = os.path.basename(frame.filename)
        if name.startswith("test_") and name.endswith(".py"):
            return os.path.abspath(frame.filename)
    return None


def _mode():
    mode = os.environ.get(MODE_VARIABLE, "use")
    if mode not in ("use", "update", "off"):
        raise ValueError(f"{MODE_VARIABLE} is 'use', 'update' or 'off', not '{mode}'")
    return mode


class Reference:
    """Where Cycles' passes for one render of one scene live."""

    def __init__(self, scene, width, height, transparent):
        self.script = _calling_script()
        self.path = None
        dump = os.environ.get(MODE_VARIABLE + "_DUMP")
        if self.script is None or (_mode() == "off" and not dump):
            return  # nothing to read or store: no fingerprint to compute
        with open(self.script, "rb") as f:
            self.script_sha = hashlib.sha256(f.read()).hexdigest()
        text = f"{fingerprint(scene)}\nsize {width}x{height} transparent={transparent}\nscript {self.script_sha}"
        self.key = hashlib.sha256(text.encode()).hexdigest()[:24]
        if dump:  # a folder to write fingerprints into, to see why two differ
            os.makedirs(dump, exist_ok=True)
            path = os.path.join(dump, self.key + ".txt")
            while os.path.exists(path):
                path = path[:-4] + "+.txt"
            with open(path, "w") as f:
                f.write(text)
        self.folder = os.path.join(ROOT, bpy.app.version_string.split(" ")[0],
                                   os.path.splitext(os.path.basename(self.script))[0])
        self.path = os.path.join(self.folder, self.key + ".npz")

    def load(self):
        """The stored passes, or None (after saying why) when there are none."""
        if self.path is None or _mode() != "use":
            return None
        if not os.path.exists(self.path):
            print(f"Cycles reference {os.path.relpath(self.path, REPO)} is not stored: rendering Cycles "
                  f"(scripts/build/cycles_references.sh stores it)")
            return None
        with np.load(self.path) as stored:
            return {k: (stored[k].astype(np.float32) if k in stored.files else None)
                    for k in ("rgba", "depth", "normal")}

    _cleared = set()

    def store(self, passes):
        if self.path is None or _mode() != "update":
            return
        if self.folder not in Reference._cleared:
            # The first reference a script stores replaces all it stored before.
            Reference._cleared.add(self.folder)
            if os.path.isdir(self.folder):
                for name in os.listdir(self.folder):
                    os.remove(os.path.join(self.folder, name))
        os.makedirs(self.folder, exist_ok=True)
        arrays = {k: np.asarray(v, dtype=_stored_type(k, v)) for k, v in passes.items() if v is not None}
        np.savez_compressed(self.path, **arrays)
        manifest = os.path.join(self.folder, "manifest.json")
        entries = {}
        if os.path.exists(manifest):
            with open(manifest) as f:
                entries = json.load(f)
        entries["script"] = os.path.relpath(self.script, REPO)
        entries["script_sha256"] = self.script_sha
        entries["blender"] = bpy.app.version_string
        entries.setdefault("references", [])
        if self.key not in entries["references"]:
            entries["references"].append(self.key)
        with open(manifest, "w") as f:
            json.dump(entries, f, indent=1)
            f.write("\n")
