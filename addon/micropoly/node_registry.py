# SPDX-License-Identifier: GPL-3.0-or-later
"""Which function compiles each node type.

Node families each keep their node types in a NODES table: inputs
(node_inputs), converters (node_converters), vectors and displacement
(node_vectors), images and sky (node_images), procedural noise
(node_noise), patterns and colour (node_textures). A family takes the
NodeCompiler and a node and returns the node's outputs; it imports only
node_kinds, never the compiler, so no two modules import each other. A new
node is a function in its family and a line in its table. Shader nodes
(BSDFs, Mix and Add Shader) are the compiler's own: they add closures
rather than return values."""

from . import node_converters, node_images, node_inputs, node_noise, node_textures, node_vectors

FAMILIES = (node_inputs, node_converters, node_vectors, node_images, node_noise, node_textures)


def _merged():
    table = {}
    for family in FAMILIES:
        for node_type, emit in family.NODES.items():
            if node_type in table:
                raise RuntimeError(f"node type {node_type} is in two families ({family.__name__})")
            table[node_type] = emit
    return table


VALUE_NODES = _merged()


def emitter(node_type):
    """The function compiling nodes of this type, or None (unsupported)."""
    return VALUE_NODES.get(node_type)
