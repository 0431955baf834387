"""Scene.mesh_to_prototype and add_instances from Python: arrays of
instances land in the scene, render like the same meshes placed one by one,
and malformed arrays are refused with a message, never a crash; Attribute
nodes' per-object values convert as Cycles converts them."""

import numpy as np
import pytest

from micropoly import _native
from scene_helpers import look_at

POINTS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                   [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=np.float32) * 0.4
FACES = np.array([0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 2, 3, 7, 6, 1, 2, 6, 5, 0, 4, 7, 3], dtype=np.int32)
COUNTS = np.full(6, 4, dtype=np.int32)


def placements(n):
    m = np.tile(np.identity(4, dtype=np.float32), (n, 1, 1))
    m[:, 0, 3] = np.linspace(-3.0, 3.0, n)
    m[:, 2, 3] = np.linspace(-1.0, 1.0, n)
    return m


def base():
    s = _native.Scene()
    s.settings.width, s.settings.height = 96, 64
    s.set_camera(look_at((0.0, -8.0, 2.0), (0.0, 0.0, 0.0)), fov_degrees=60.0)
    s.add_light("distant", direction=[-0.3, 0.5, -1.0])
    return s


def test_instances_render_like_meshes_placed_one_by_one():
    n = 5
    inst = base()
    inst.add_mesh("cube", POINTS, COUNTS, FACES, subdivision=True)
    proto = inst.mesh_to_prototype(-1, "cube")
    inst.add_instances(proto, placements(n), random=np.linspace(0, 1, n, dtype=np.float32))
    assert (inst.prototype_count, inst.instance_count, inst.mesh_count) == (1, n, 0)
    copies = base()
    for m in placements(n):
        copies.add_mesh("cube", POINTS, COUNTS, FACES, subdivision=True, object_to_world=m)
    r = _native.Renderer()
    a, b = r.render(inst), r.render(copies)
    assert a["stats"]["instances"] == n
    rgba_a, rgba_b = np.asarray(a["rgba"]), np.asarray(b["rgba"])
    assert (rgba_a[..., 3] > 0).mean() > 0.02  # five cubes in view
    mse = float(np.mean((rgba_a - rgba_b) ** 2))
    assert mse == 0.0 or 10 * np.log10(1.0 / mse) >= 60.0
    assert np.array_equal(rgba_a[..., 3], rgba_b[..., 3])


@pytest.mark.parametrize("call, needle", [
    (lambda s: s.add_instances(3, placements(2)), "no prototype 3"),
    (lambda s: s.add_instances(0, np.zeros((2, 3, 4), np.float32)), "(steps, 4, 4)"),
    (lambda s: s.add_instances(0, placements(2), random=np.zeros(3, np.float32)), "random needs 1 value"),
    (lambda s: s.add_instances(0, placements(2), object_color=np.zeros(2, np.float32)), "object_color needs 4"),
    (lambda s: s.add_instances(0, placements(2), motion_object_to_world=np.zeros((3, 2, 4, 4), np.float32)),
     "(instances, steps, 4, 4)"),
    (lambda s: s.mesh_to_prototype(4), "no mesh 4"),
])
def test_malformed_instances_are_refused(call, needle):
    s = base()
    s.add_mesh("cube", POINTS, COUNTS, FACES)
    s.mesh_to_prototype(-1)
    with pytest.raises(RuntimeError, match=None) as e:
        call(s)
    assert needle in str(e.value)


def test_an_instance_of_nan_is_refused_at_validation():
    s = base()
    s.add_mesh("cube", POINTS, COUNTS, FACES)
    s.mesh_to_prototype(-1)
    m = placements(1)
    m[0, 0, 3] = np.nan
    s.add_instances(0, m)
    with pytest.raises(RuntimeError) as e:
        s.validate()
    assert "instance '0'" in str(e.value)


def test_malformed_attributes_are_refused_with_a_message():
    s = base()
    with pytest.raises(RuntimeError, match="attributes"):
        s.add_mesh("cube", POINTS, COUNTS, FACES, attributes=np.zeros(6, dtype=np.float32))
    s.add_mesh("cube", POINTS, COUNTS, FACES, attributes=np.full((2, 4), np.nan, dtype=np.float32))
    proto = s.mesh_to_prototype(-1, "cube")
    with pytest.raises(RuntimeError, match="attributes"):
        s.add_instances(proto, placements(3), attributes=np.zeros((2, 1, 4), dtype=np.float32))
    with pytest.raises(RuntimeError, match="attributes"):
        s.add_instances(proto, placements(3), attributes=np.zeros((3, 1, 3), dtype=np.float32))
    s.add_instances(proto, placements(3), attributes=np.zeros((3, 2, 4), dtype=np.float32))
    s.validate()  # NaN read as zero
    assert s.instance_count == 3


class Owner(dict):
    """A custom-property holder with property paths, as an ID is."""

    def __init__(self, props, paths):
        super().__init__(props)
        self.paths = paths

    def path_resolve(self, name):
        if name not in self.paths:
            raise ValueError(name)
        return self.paths[name]


def test_attribute_values_convert_as_cycles_converts_them():
    from micropoly import export_attributes as ea

    o = Owner({"f": 0.25, "i": 3, "b": True, "v2": [1, 2], "c": (0.1, 0.2, 0.3, 0.4), "s": "12", "long": [1] * 5},
              {"color": (0.5, 0.6, 0.7, 1.0), "f": 9.0})
    assert ea.rgba(o, "f") == (0.25, 0.25, 0.25, 1.0)  # the custom property before the path
    assert ea.rgba(o, "i") == (3.0, 3.0, 3.0, 1.0)
    assert ea.rgba(o, "b") == (1.0, 1.0, 1.0, 1.0)
    assert ea.rgba(o, "v2") == (1.0, 2.0, 0.0, 1.0)
    assert ea.rgba(o, "c") == (0.1, 0.2, 0.3, 0.4)
    assert ea.rgba(o, "color") == (0.5, 0.6, 0.7, 1.0)
    assert ea.rgba(o, "s") is None and ea.rgba(o, "long") is None and ea.rgba(o, "missing") is None
    assert ea.rgba(None, "f") is None

    class Obj(Owner):
        data = Owner({"m": 2.0}, {})

    obj = Obj({"f": 0.5}, {})
    values = ea.object_values([("f", "OBJECT"), ("m", "INSTANCER"), ("none", "OBJECT"), ("f", "POINT")], obj)
    np.testing.assert_array_equal(values, [[0.5, 0.5, 0.5, 1.0], [2.0, 2.0, 2.0, 1.0], [0, 0, 0, 0], [0, 0, 0, 0]])
