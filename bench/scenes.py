"""Benchmark scenes, generated as RIB files (so the CLI renders them on any machine).

Each function returns RIB text. Camera conventions are RenderMan's: the
transform before WorldBegin maps world to camera space (left-handed, +z ahead).
"""

import math
import os

HEADER = """Format {w} {h} 1
PixelSamples {sx} {sy}
PixelFilter "gaussian" 2 2
ShadingRate {rate}
Projection "perspective" "fov" [{fov}]
Clipping 0.01 1000
"""

LIGHTS = """LightSource "ambientlight" 1 "intensity" [0.08]
LightSource "distantlight" 2 "intensity" [0.9] "from" [0 0 0] "to" [1 -1.5 2]
LightSource "pointlight" 3 "intensity" [12] "from" [-3 4 -3]
"""


def _header(w, h, spp, rate, fov):
    sx = int(math.isqrt(spp))
    while spp % sx:
        sx -= 1
    return HEADER.format(w=w, h=h, sx=sx, sy=spp // sx, rate=rate, fov=fov)


def _array(values, per_line=12):
    items = [f"{v:.6g}" if isinstance(v, float) else str(v) for v in values]
    lines = [" ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return "[" + "\n ".join(lines) + "]"


def dense_subdiv(w=1920, h=1080, spp=4, rate=1.0, n=48, tilt=25, distance=3.2):
    """A wavy Catmull-Clark sheet of n x n faces filling about half the frame
    (tilted 25 degrees; at 78 degrees it is seen at a grazing angle)."""
    pts, nverts, verts = [], [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = -1.0 + 2.0 * i / n, -1.0 + 2.0 * j / n
            z = 0.08 * math.sin(7.0 * x) * math.cos(5.0 * y)
            pts += [x, y, z]
    for j in range(n):
        for i in range(n):
            v = j * (n + 1) + i
            nverts.append(4)
            verts += [v, v + 1, v + n + 2, v + n + 1]
    return (_header(w, h, spp, rate, 40) +
            f"Translate 0 0 {distance}\nRotate -{tilt} 1 0 0\nWorldBegin\n" + LIGHTS +
            'AttributeBegin\nColor [0.7 0.55 0.4]\nSurface "plastic" "Ks" [0.4] "roughness" [0.15]\n'
            f'SubdivisionMesh "catmull-clark" {_array(nverts)} {_array(verts)} '
            '["interpolateboundary"] [0 0] [] [] '
            f'"P" {_array(pts)}\nAttributeEnd\nWorldEnd\n')


def teapot(w=1920, h=1080, spp=4, rate=1.0, teapot_path="teapot_patches.rib"):
    """The Utah teapot (32 Bezier patches), filling most of the frame."""
    return (_header(w, h, spp, rate, 35) +
            "Translate 0 -0.2 9\nRotate -110 1 0 0\nRotate 30 0 0 1\nWorldBegin\n" + LIGHTS +
            'AttributeBegin\nColor [0.8 0.3 0.2]\nSurface "plastic" "Ks" [0.5] "roughness" [0.1]\n'
            "Translate 0 0 -1.5\n"
            f'ReadArchive "{teapot_path}"\nAttributeEnd\nWorldEnd\n')


def eye_split_plane(w=1920, h=1080, spp=4, rate=1.0):
    """A ground plane running under and far behind the camera: its patches
    straddle the eye plane and need eye-splitting."""
    return (_header(w, h, spp, rate, 60) +
            "Rotate 10 1 0 0\nTranslate 0 1 0\nWorldBegin\n" + LIGHTS +
            'AttributeBegin\nColor [0.5 0.6 0.5]\nSurface "matte"\n'
            'Polygon "P" [-200 0 -200  200 0 -200  200 0 200  -200 0 200]\n'
            "AttributeEnd\nWorldEnd\n")


def depth_stack(w=1920, h=1080, spp=4, rate=1.0, layers=16):
    """16 overlapping curved Catmull-Clark layers, front to back, each covering
    most of the frame: depth complexity 16."""
    out = [_header(w, h, spp, rate, 45), "Translate 0 0 4\nWorldBegin\n", LIGHTS]
    pts = []
    n = 4
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = -2.2 + 4.4 * i / n, -1.4 + 2.8 * j / n
            pts += [x, y, 0.15 * math.sin(2.0 * x)]
    nverts = [4] * (n * n)
    verts = []
    for j in range(n):
        for i in range(n):
            v = j * (n + 1) + i
            verts += [v, v + 1, v + n + 2, v + n + 1]
    for k in range(layers):
        g = 0.3 + 0.6 * k / max(layers - 1, 1)
        out.append(f"AttributeBegin\nTranslate 0 0 {0.1 * k:.3f}\nColor [{g:.3f} 0.4 {1 - g:.3f}]\n"
                   'Surface "matte"\n'
                   f'SubdivisionMesh "catmull-clark" {_array(nverts)} {_array(verts)} [] [] [] [] '
                   f'"P" {_array(pts)}\nAttributeEnd\n')
    out.append("WorldEnd\n")
    return "".join(out)


def write_all(folder, teapot_source):
    """Writes every scene into `folder`; returns {name: path}."""
    os.makedirs(folder, exist_ok=True)
    # The teapot's 32 patches, taken from the test scene.
    with open(teapot_source) as f:
        patches = [line.strip() for line in f if line.strip().startswith("Patch ")]
    with open(os.path.join(folder, "teapot_patches.rib"), "w") as f:
        f.write("\n".join(patches) + "\n")
    scenes = {
        "dense_subdiv": dense_subdiv(),
        # For the bound & split memory sweep: a 262k-face mesh at 4K, whose
        # widest split level is wide enough to show breadth-first's memory.
        "wide_subdiv_4k": dense_subdiv(w=3840, h=2160, spp=1, n=512),
        "grazing_sheet": dense_subdiv(tilt=78, distance=2.2),
        "teapot": teapot(),
        "eye_split_plane": eye_split_plane(),
        "depth_stack_16": depth_stack(),
    }
    paths = {}
    for name, rib in scenes.items():
        path = os.path.join(folder, name + ".rib")
        with open(path, "w") as f:
            f.write(rib)
        paths[name] = path
    return paths


def _cube_shell(n):
    """A cube of half size 1 with n x n quads per side, as (points, counts,
    indices) with shared vertices: a closed Catmull-Clark shell."""
    index, pts, faces = {}, [], []

    def vertex(p):
        key = tuple(round(c * 2 * n) for c in p)
        if key not in index:
            index[key] = len(pts)
            pts.append(p)
        return index[key]

    for axis in range(3):
        for sign in (-1.0, 1.0):
            u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
            for j in range(n):
                for i in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = sign
                        p[u_axis] = -1.0 + 2.0 * (i + di) / n
                        p[v_axis] = -1.0 + 2.0 * (j + dj) / n
                        quad.append(vertex(p))
                    faces.append(quad if sign > 0 else quad[::-1])
    return pts, [4] * len(faces), [v for f in faces for v in f]


def nested_shells(shells, w=1920, h=1080, spp=4, rate=1.0, n=6):
    """The camera inside `shells` closed, nested Catmull-Clark shells (cubes
    of n x n faces per side, rounded by subdivision into blobs), the
    innermost of half size 2, each next 0.1 larger: only the innermost is
    seen. Depth complexity grows with the number of shells."""
    pts, counts, indices = _cube_shell(n)
    out = [_header(w, h, spp, rate, 70), "Rotate -20 0 1 0\nRotate 10 1 0 0\nWorldBegin\n", LIGHTS]
    for k in range(shells):
        s = 2.0 + 0.1 * k
        g = 0.3 + 0.6 * k / max(shells - 1, 1)
        out.append(f"AttributeBegin\nScale {s:.3f} {0.8 * s:.3f} {1.2 * s:.3f}\nColor [{g:.3f} 0.5 {1 - g:.3f}]\n"
                   'Surface "matte"\n'
                   f'SubdivisionMesh "catmull-clark" {_array(counts)} {_array(indices)} [] [] [] [] '
                   f'"P" {_array([c for p in pts for c in p])}\nAttributeEnd\n')
    out.append("WorldEnd\n")
    return "".join(out)
