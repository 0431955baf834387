# SPDX-License-Identifier: GPL-3.0-or-later
"""Image nodes: Image Texture, Environment Texture and Sky Texture, which
read images the export uploads (the compiler's resources) or, for the sky,
a texture the native module precomputes as Cycles does.

Each function takes the NodeCompiler and the node and returns the node's
outputs by socket identifier as (expression, kind, value range or None);
NODES maps node types to them (node_registry.py)."""

import math

from .node_kinds import FLOAT, VEC

IMAGE_INTERPOLATION = {"Linear": 0, "Closest": 1, "Cubic": 2, "Smart": 2}  # Cycles renders Smart as Cubic
IMAGE_EXTENSION = {"REPEAT": 0, "EXTEND": 1, "CLIP": 2, "MIRROR": 3}
# Sky Texture models with a precomputed texture (native nishita_sky_texture).
SKY_MODELS = ("NISHITA", "SINGLE_SCATTERING", "MULTIPLE_SCATTERING")
# A world is baked by sampling its map's texel centres (512 texels around by
# default); the sun's disc, smaller than a texel, has its light spread over
# 2.5 texels of that map so every bake holds it to within 1%
# (kernels/textures/mp_tex_sky.h).
WORLD_SUN_SPREAD = 2.5 * 2.0 * math.pi / 512


def emit_image(c, node):
    c.headers.add("mp_tex_image.h")
    index, value_range = c.resources.image(node.image, lambda what: c.warn(node, what))
    interp = IMAGE_INTERPOLATION.get(node.interpolation, 0)
    ext = IMAGE_EXTENSION.get(node.extension, 0)
    images = f"g->images, g->image_count, g->texels, {index}"
    if interp == IMAGE_INTERPOLATION["Closest"]:
        # Closest reads the texel under the point at any distance, as in Cycles.
        vec = c.input(node, "Vector", VEC)[0] if node.inputs["Vector"].is_linked else c.uv()
        dx = dy = "(float3)(0.0f)"
    else:
        # Filtered over the micropolygon's footprint (mp_tex_image_area).
        vec, dx, dy = c.with_footprint(node, "Vector", c.uv_at())
    if node.projection == "BOX":
        # Blended by the object-space normal, as Cycles does.
        blend = c.param(float(node.projection_blend))
        rgba = c.fn.temp("float4", f"mp_tex_image_box_area({images}, {vec}, {dx}, {dy}, g->N, {blend}, {interp}, "
                                   f"{ext})")[0]
    else:
        if node.projection in ("SPHERE", "TUBE"):
            proj = f"mp_image_{node.projection.lower()}_uv"
            # The seam's jump of a whole turn is no footprint.
            dx = f"mp_image_wrapped_change({proj}({vec} + {dx}) - {proj}({vec}))"
            dy = f"mp_image_wrapped_change({proj}({vec} + {dy}) - {proj}({vec}))"
            vec = c.fn.temp("float2", f"{proj}({vec})")[0]
        rgba = c.fn.temp("float4", f"mp_tex_image_area({images}, ({vec}).x, ({vec}).y, ({dx}).xy, ({dy}).xy, "
                                   f"{interp}, {ext})")[0]
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


def emit_environment(c, node):
    """An Environment Texture: the image at a direction (the world's
    own by default), equirectangular or mirror ball, wrapping in longitude."""
    c.headers.add("mp_tex_image.h")
    index, value_range = c.resources.image(node.image, lambda what: c.warn(node, what))
    vec = c.input(node, "Vector", VEC)[0] if node.inputs["Vector"].is_linked else "g->generated"
    proj = "mirror_ball" if node.projection == "MIRROR_BALL" else "equirect"
    uv = c.fn.temp("float2", f"mp_env_{proj}_uv({vec})")[0]
    interp = IMAGE_INTERPOLATION.get(node.interpolation, 0)
    images = f"g->images, g->image_count, g->texels, {index}"
    rgba = c.fn.temp("float4", f"mp_tex_image({images}, ({uv}).x, ({uv}).y, {interp}, 0)")[0]
    return {"Color": (f"{rgba}.xyz", VEC, value_range)}


def emit_sky(c, node):
    """A Sky Texture of a physical model (Nishita before 5.0; Single and
    Multiple Scattering in 5.0): a texture precomputed by the native
    module as Cycles does, and the sun's disc (kernels/textures/mp_tex_sky.h)."""
    sky_type = node.sky_type
    if sky_type not in SKY_MODELS:
        # Blender's default world grey stands in for the sky.
        c.warn(node, f"the {sky_type.replace('_', ' ').title()} sky model is not supported; it gives grey")
        return {"Color": ("(float3)(0.050876f)", VEC, None)}
    from . import _native  # the precomputation is native; compiling alone needs no module

    c.headers.add("mp_tex_sky.h")
    params = dict(model=sky_type, sun_disc=bool(node.sun_disc), sun_size=float(node.sun_size),
                  sun_intensity=float(node.sun_intensity), sun_elevation=float(node.sun_elevation),
                  sun_rotation=float(node.sun_rotation), altitude=float(node.altitude),
                  air=float(node.air_density),
                  dust=float(getattr(node, "aerosol_density", getattr(node, "dust_density", 1.0))),
                  ozone=float(node.ozone_density))
    spread = WORLD_SUN_SPREAD if c.world else 0.0
    sun = _native.nishita_sky_sun(spread=spread, **params)
    key = ("sky",) + tuple(sorted(params.items()))
    index = c.resources.array_image(key, lambda: _native.nishita_sky_texture(**params)[0])
    # The node's Vector socket is hidden in every version (its lookup by
    # name fails from 4.0); when it is linked all the same, it is the direction.
    vector = next((s for s in node.inputs if s.identifier == "Vector"), None)
    vec = c.input(node, list(node.inputs).index(vector), VEC)[0] if vector is not None and vector.is_linked \
        else "g->generated"
    name = f"sky{c.fn.counter}"
    c.fn.counter += 1
    fields = [c.param3(sun["sun_bottom"]), c.param3(sun["sun_top"]), c.param3(sun["sun_flux"])]
    fields += [c.param(sun[k]) for k in ("sun_elevation", "sun_rotation", "sun_diameter", "sun_intensity",
                                            "earth_angle", "spread")]
    fields.append(str(int(sun["layout"])))
    c.fn.lines.append(f"  MpSky {name} = {{{', '.join(fields)}}};")
    images = f"g->images, g->image_count, g->texels, {index}"
    return {"Color": c.fn.temp(VEC, f"mp_tex_sky({images}, {vec}, &{name})")}


NODES = {
    "TEX_IMAGE": emit_image,
    "TEX_ENVIRONMENT": emit_environment,
    "TEX_SKY": emit_sky,
}
