"""The native module's Scene entry points given random numpy arrays.

Blender add-ons and scripts hand micropoly._native whatever arrays they hold:
any shape, any dtype (float64, int8, bool, object, non-contiguous views, 0-d
scalars, large arrays), NaNs, infinities and out-of-range indices. Every call
must either succeed or raise a Python exception; a crash would take Blender
down with it. Scenes that Scene.validate() accepts are also written as RIB
and read back (the host-side path that needs no device), so validation is
shown to let nothing through that the rest of the module cannot handle.

The cases are drawn from a fixed seed, so a failure names a case that can be
replayed by its number.
"""

import os

import numpy as np
import pytest

from micropoly import _native

CASES = 1200
SEED = 20261124

FLOAT_SPECIALS = np.array([np.nan, np.inf, -np.inf, 3.0e38, -3.0e38, 1e-45, 0.0, -0.0, 1e300], dtype=np.float64)
INT_SPECIALS = np.array([-1, -2, 2**31 - 1, -(2**31), 0, 1, 3, 2**40, -(2**40)], dtype=np.int64)


def values(rng, shape, kind):
    """An array of `shape` and a random dtype; floats with NaN/Inf/huge
    values sprinkled in, integers near and far outside the valid range."""
    if kind == "float":
        a = rng.normal(0.0, 2.0, size=shape)
        mask = rng.random(size=shape) < 0.05
        a[mask] = rng.choice(FLOAT_SPECIALS, size=int(mask.sum()))
    else:
        a = rng.integers(-2, 12, size=shape).astype(np.float64)
        mask = rng.random(size=shape) < 0.05
        a[mask] = rng.choice(INT_SPECIALS, size=int(mask.sum()))
    dtype = rng.choice(["float32", "float64", "int32", "int64", "int8", "uint8", "bool", "object", "float16"])
    with np.errstate(all="ignore"):
        if dtype == "object":
            out = a.astype(object)
            if out.size and rng.random() < 0.3:  # not every object is a number
                out.flat[int(rng.integers(out.size))] = rng.choice(["x", None, (1, 2), 1.5])
            return out
        return a.astype(dtype)


def array(rng, good_shape, kind="float"):
    """Mostly an array of the expected shape, otherwise something near it:
    a wrong or extra dimension, an empty or 0-d array, a non-contiguous view,
    a Python list, or a large array."""
    r = rng.random()
    if r < 0.45:
        shape = good_shape
    elif r < 0.55:
        shape = tuple(max(0, d + int(rng.integers(-1, 2))) for d in good_shape)
    elif r < 0.62:
        shape = good_shape + (int(rng.integers(1, 3)),)
    elif r < 0.68:
        shape = good_shape[1:] or (0,)
    elif r < 0.74:
        return values(rng, (), kind)  # 0-d
    elif r < 0.80:
        shape = (0,) + good_shape[1:]
    elif r < 0.88:  # a strided view of a larger array
        big = values(rng, tuple(2 * d + 1 for d in good_shape), kind)
        return big[tuple(slice(1, None, 2) for _ in good_shape)]
    elif r < 0.94:
        return values(rng, good_shape, kind).tolist()
    else:
        shape = (good_shape[0] * 50 + 20000,) + good_shape[1:] if good_shape else (20000,)
    return values(rng, shape, kind)


def small_vector(rng, n):
    r = rng.random()
    if r < 0.7:
        return [float(x) for x in values(rng, (n,), "float").astype(np.float64)]
    if r < 0.8:
        return [0.0] * int(rng.integers(0, 6))
    if r < 0.9:
        return values(rng, (n,), "float")
    return "abc"


def scalar(rng, kind="float"):
    r = rng.random()
    if r < 0.6:
        return float(rng.normal()) if kind == "float" else int(rng.integers(-2, 6))
    if r < 0.85:
        return (float(rng.choice(FLOAT_SPECIALS)) if kind == "float" else int(rng.choice(INT_SPECIALS)))
    if r < 0.95:
        return np.float64(rng.normal()) if kind == "float" else np.int8(rng.integers(-3, 4))
    return None


def add_mesh(rng, scene):
    n_points = int(rng.integers(0, 40))
    n_faces = int(rng.integers(0, 20))
    counts = rng.integers(3, 6, size=n_faces)
    corners = int(counts.sum())
    kwargs = dict(
        subdivision=bool(rng.random() < 0.4),
        material=scalar(rng, "int"),
        double_sided=bool(rng.random() < 0.5),
    )
    optional = {
        "object_to_world": lambda: array(rng, (4, 4)),
        "face_materials": lambda: array(rng, (n_faces,), "int"),
        "crease_vertices": lambda: array(rng, (6,), "int"),
        "crease_sharpness": lambda: array(rng, (3,)),
        "corner_vertices": lambda: array(rng, (2,), "int"),
        "corner_sharpness": lambda: array(rng, (2,)),
        "hole_faces": lambda: array(rng, (1,), "int"),
        "uv_layers": lambda: array(rng, (int(rng.integers(1, 3)), corners, 2)),
        "corner_normals": lambda: array(rng, (corners, 3)),
        "texspace_location": lambda: small_vector(rng, 3),
        "texspace_size": lambda: small_vector(rng, 3),
        "object_color": lambda: small_vector(rng, 4),
        "boundary": lambda: str(rng.choice(["none", "edge_only", "edge_and_corner", "bogus"])),
        "pass_index": lambda: scalar(rng),
    }
    for key, make in optional.items():
        if rng.random() < 0.3:
            kwargs[key] = make()
    indices = rng.integers(0, max(n_points, 1), size=corners)
    scene.add_mesh(
        "m",
        array(rng, (n_points, 3)),
        counts if rng.random() < 0.7 else array(rng, (n_faces,), "int"),
        indices if rng.random() < 0.7 else array(rng, (corners,), "int"),
        **kwargs,
    )
    if rng.random() < 0.2:
        steps = int(rng.integers(0, 4))
        scene.set_mesh_motion(
            scalar(rng, "int"), points=array(rng, (steps, n_points, 3)), object_to_world=array(rng, (steps, 4, 4))
        )


def add_curves(rng, scene):
    n_points = int(rng.integers(0, 30))
    offsets = np.sort(rng.integers(0, n_points + 1, size=int(rng.integers(1, 5)))).astype(np.int32)
    kwargs = {}
    if rng.random() < 0.5:
        kwargs["point_layers"] = array(rng, (int(rng.integers(1, 10)), n_points, 2))
    if rng.random() < 0.2:
        steps = int(rng.integers(0, 4))
        kwargs["motion_points"] = array(rng, (steps, n_points, 3))
    kwargs["ribbons"] = bool(rng.random() < 0.5)
    scene.add_curves("c", array(rng, (n_points, 3)), array(rng, (n_points,)),
                     offsets if rng.random() < 0.7 else array(rng, (int(rng.integers(0, 5)),), "int"), **kwargs)


def one_call(rng, scene):
    which = rng.choice(["mesh", "mesh", "mesh", "curves", "camera", "motion", "dof", "material", "program", "light",
                        "image", "world", "settings"])
    if which == "mesh":
        add_mesh(rng, scene)
    elif which == "curves":
        add_curves(rng, scene)
    elif which == "camera":
        scene.set_camera(array(rng, (4, 4)), orthographic=bool(rng.random() < 0.3), fov_degrees=scalar(rng),
                         clip_near=scalar(rng), clip_far=scalar(rng),
                         screen_window=small_vector(rng, 4) if rng.random() < 0.3 else [])
    elif which == "motion":
        steps = int(rng.integers(0, 5))
        scene.set_motion(scalar(rng, "int") if rng.random() < 0.3 else steps,
                         camera_world_to_camera=array(rng, (steps, 4, 4)), shutter_curve=array(rng, (5,)))
    elif which == "dof":
        scene.set_depth_of_field(scalar(rng), scalar(rng), blades=scalar(rng, "int"), rotation=scalar(rng),
                                 ratio=scalar(rng))
    elif which == "material":
        scene.add_material(name="mat", model=str(rng.choice(["constant", "matte", "plastic", "principled", "x"])),
                           color=small_vector(rng, 3), opacity=small_vector(rng, 3), roughness=scalar(rng),
                           emission=small_vector(rng, 3), program=scalar(rng, "int"),
                           program_displaces=bool(rng.random() < 0.5), displacement_bound=scalar(rng))
    elif which == "program":
        scene.add_material_program("p", str(rng.choice(["", "float3 f(", "\x00", "void mp_node_surface() {}"])))
    elif which == "light":
        scene.add_light(str(rng.choice(["ambient", "distant", "point", "spot", "area", "sun"])),
                        color=small_vector(rng, 3), intensity=scalar(rng), position=small_vector(rng, 3),
                        direction=small_vector(rng, 3), cone_angle=scalar(rng), size_u=scalar(rng),
                        shape=str(rng.choice(["rectangle", "ellipse", "disk"])), axis_u=small_vector(rng, 3),
                        radius=scalar(rng), angle=scalar(rng))
    elif which == "image":
        h, w = int(rng.integers(0, 6)), int(rng.integers(0, 6))
        scene.add_image("img", array(rng, (h, w, 4)), srgb=bool(rng.random() < 0.5))
    elif which == "world":
        h, w = int(rng.integers(0, 4)), int(rng.integers(0, 8))
        scene.set_world(program=scalar(rng, "int"), bake_width=scalar(rng, "int"),
                        radiance=array(rng, (h, w, 4)) if rng.random() < 0.6 else np.zeros(0, np.float32),
                        diffuse=scalar(rng), glossy=scalar(rng))
    else:
        s = scene.settings
        name = str(rng.choice(["width", "height", "samples_x", "samples_y", "shading_rate", "filter_width",
                               "crop_x0", "crop_x1", "max_grid_size", "max_split_depth", "world_probes",
                               "pixel_aspect", "shadow_memory_mib"]))
        setattr(s, name, scalar(rng, "int" if name in ("width", "height", "samples_x", "samples_y", "max_grid_size",
                                                        "max_split_depth", "world_probes") else "float"))


# Exceptions a bad argument may raise: the module's Error (a RuntimeError),
# pybind11's conversion errors (TypeError), numpy's cast errors (ValueError),
# and indexing/overflow errors from the bindings.
EXPECTED = (RuntimeError, TypeError, ValueError, OverflowError, IndexError, MemoryError)


def test_random_arrays_either_work_or_raise(tmp_path):
    rng = np.random.default_rng(SEED)
    outcomes = {"ok": 0, "raised": 0, "valid": 0, "invalid": 0, "written": 0}
    for case in range(CASES):
        scene = _native.Scene()
        for _ in range(int(rng.integers(1, 5))):
            try:
                one_call(rng, scene)
                outcomes["ok"] += 1
            except EXPECTED:
                outcomes["raised"] += 1
            except Exception as e:  # anything else is a binding that lets a foreign error out
                pytest.fail(f"case {case}: unexpected {type(e).__name__}: {e}")
        try:
            scene.validate()
        except RuntimeError:
            outcomes["invalid"] += 1
            continue
        outcomes["valid"] += 1
        # A valid scene must also write (validation is what the writer
        # checks first) and read back.
        path = os.path.join(tmp_path, f"case{case}.rib")
        _native.write_rib(scene, path)
        back = _native.read_rib(path)
        back.validate()
        assert back.mesh_count == scene.mesh_count, f"case {case}"
        outcomes["written"] += 1
    print(outcomes)
    # The draw must reach both sides of every check to mean anything.
    assert outcomes["ok"] > CASES and outcomes["raised"] > CASES // 4, outcomes
    assert outcomes["valid"] > CASES // 10 and outcomes["invalid"] > CASES // 4, outcomes
