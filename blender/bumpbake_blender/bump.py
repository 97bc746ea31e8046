"""Bump nodes to normal maps: a Bump node whose Height comes from an Image Texture becomes that
height baked by bumpbake through the object's mesh into a tangent-space normal map, wired
through a Normal Map node into what the Bump node fed. What cannot be converted exactly is
listed, never skipped in silence."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import bpy
import numpy as np

from . import mesh_arrays

# Cycles reads an Image Texture's colour into a float socket as its luminance (Rec. 709 weights
# of the scene-linear colour, Blender's default colour management).
LUMA = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
WRAP = {"REPEAT": "repeat", "EXTEND": "clamp", "CLIP": "clamp", "MIRROR": "mirror"}
FRAME_LABEL = "bumpbake: original Bump (muted)"


@dataclass
class Source:
    """Where a Bump node's height comes from."""

    bump: bpy.types.Node
    image_node: bpy.types.Node
    socket: str  # "Color" or "Alpha"
    uv_map: str
    chain: list = field(default_factory=list)  # reroutes between, kept with the Bump node


@dataclass
class Report:
    converted: list = field(default_factory=list)  # (material, bump node, image made, ms)
    wired: list = field(default_factory=list)  # Wired, to undo
    skipped: list = field(default_factory=list)  # (material, bump node, why)
    seconds: float = 0.0

    def line(self) -> str:
        parts = [f"{len(self.converted)} Bump node(s) converted"]
        if self.skipped:
            listed = "; ".join(f"{m}/{b}: {why}" for m, b, why in self.skipped)
            parts.append(f"{len(self.skipped)} left as they are: {listed}")
        return ", ".join(parts) + f" ({self.seconds:.2f} s)"


def _upstream(socket):
    """The output linked into `socket` past reroutes, and the reroutes passed."""
    chain = []
    while socket.is_linked:
        link = socket.links[0]
        node = link.from_node
        if node.type == "REROUTE":
            chain.append(node)
            socket = node.inputs[0]
            continue
        return link.from_socket, chain
    return None, chain


def _uv_map_of(image_node, obj) -> str | None:
    """The UV map an Image Texture node reads: its Vector input's UV Map node, or the mesh's
    active render map when nothing is linked; None when it reads anything else."""
    vec, _ = _upstream(image_node.inputs["Vector"])
    uv_layers = obj.data.uv_layers
    default = next((u.name for u in uv_layers if u.active_render), uv_layers[0].name if len(uv_layers) else None)
    if vec is None:
        return default
    node = vec.node
    if node.type == "UVMAP":
        return node.uv_map or default
    if node.type == "TEX_COORD" and vec.name == "UV":
        return default
    return None


def find(material, obj) -> tuple[list[Source], list[tuple[str, str]]]:
    """The material's Bump nodes that can be converted, and why each other one cannot."""
    sources, skipped = [], []
    if not material.node_tree:
        return sources, skipped
    for node in material.node_tree.nodes:
        if node.type != "BUMP":
            continue
        why = None
        if node.mute:
            continue
        height, chain = _upstream(node.inputs["Height"])
        if height is None:
            why = "its Height is not linked"
        elif height.node.type != "TEX_IMAGE":
            why = f"its Height comes from a {height.node.bl_label} node, not an Image Texture"
        elif height.node.image is None:
            why = "its Image Texture has no image"
        elif height.node.image.source not in {"FILE", "GENERATED"}:
            why = f"its image is a {height.node.image.source.lower()}, not a still image"
        elif height.node.projection != "FLAT":
            why = f"its Image Texture projects {height.node.projection.lower()}, not through UVs"
        elif node.inputs["Normal"].is_linked:
            why = "its Normal input is linked (a chain of normal nodes)"
        elif node.inputs["Strength"].is_linked or node.inputs["Distance"].is_linked:
            why = "its Strength or Distance is linked, not a number"
        elif not any(link.to_node for link in node.outputs["Normal"].links):
            why = "its Normal output goes nowhere"
        if why is None:
            uv = _uv_map_of(height.node, obj)
            if uv is None:
                why = "its Image Texture reads coordinates other than a UV map (Mapping or other nodes)"
        if why is not None:
            skipped.append((node.name, why))
            continue
        sources.append(Source(bump=node, image_node=height.node, socket=height.name, uv_map=uv, chain=chain))
    return sources, skipped


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def height_of(image, socket: str) -> np.ndarray:
    """The height Cycles reads from `image` through `socket`, rows from the top."""
    w, h = image.size
    px = np.empty(w * h * image.channels, dtype=np.float32)
    image.pixels.foreach_get(px)
    px = px.reshape(h, w, image.channels)[::-1]
    if socket == "Alpha":
        return np.ascontiguousarray(px[:, :, 3] if image.channels == 4 else np.ones((h, w), np.float32))
    rgb = px[:, :, :3] if image.channels >= 3 else np.repeat(px[:, :, :1], 3, axis=2)
    if not image.is_float and image.colorspace_settings.name == "sRGB":
        rgb = srgb_to_linear(rgb)
    return np.ascontiguousarray(rgb @ LUMA, dtype=np.float32)


def normal_image(name: str, normals: np.ndarray, float_buffer: bool):
    """A Blender image of unit normals (rows from the top), encoded `n/2 + 1/2`, Non-Color, not
    yet saved or packed."""
    h, w, _ = normals.shape
    img = bpy.data.images.new(name, w, h, alpha=False, float_buffer=float_buffer)
    img.colorspace_settings.name = "Non-Color"
    # Contiguous arithmetic first, one strided copy after: NumPy's strided float loops are slow.
    encoded = normals * np.float32(0.5)
    encoded += np.float32(0.5)
    rgba = np.empty((h, w, 4), dtype=np.float32)
    rgba[:, :, 3] = 1.0
    rgba[:, :, :3] = encoded[::-1]
    img.pixels.foreach_set(rgba.reshape(-1))
    # Left in memory, as Cycles leaves its bakes: packing encodes the image (most of the
    # operator's time at 1024²), and the artist chooses to pack or save it.
    img.update()
    return img


def convert(
    obj, material, source: Source, filter: str = "central", padding: int = 16, float_buffer: bool = True
) -> tuple[bpy.types.Image, float]:
    """Bakes `source`'s height through `obj` and returns the image and the engine's time."""
    import bumpbake

    slots = {i for i, s in enumerate(obj.material_slots) if s.material == material}
    mesh = mesh_arrays.corners(obj, source.uv_map, slots)
    bump = source.bump
    height = height_of(source.image_node.image, source.socket)
    normals, info = bumpbake.bump_to_normal(
        height,
        mesh.positions,
        mesh.normals,
        mesh.uvs,
        tangents=mesh.tangents,
        distance=float(bump.inputs["Distance"].default_value),
        strength=float(bump.inputs["Strength"].default_value),
        invert=bool(bump.invert),
        uv_origin="bottom-left",
        filter=filter,
        wrap=WRAP.get(source.image_node.extension, "repeat"),
        padding=padding,
        bits=32,
        report=True,
    )
    name = f"{material.name}_{bump.name}_normal"
    return normal_image(name, normals, float_buffer), info["engine_ms"]


@dataclass
class Wired:
    """What `wire` changed, so that `unwire` can put it back."""

    material: bpy.types.Material
    source: Source
    image: bpy.types.Image
    added: list  # the nodes made
    targets: list  # the sockets the Bump node fed
    frame: bpy.types.Node | None


def wire(material, source: Source, image, keep_original: bool) -> Wired:
    """The Normal Map node in the Bump node's place; the Bump chain kept in a muted frame."""
    nt = material.node_tree
    bump = source.bump
    x, y = bump.location.x, bump.location.y - 320
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = source.image_node.interpolation
    tex.extension = source.image_node.extension
    tex.location = (x - 200, y)
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.space = "TANGENT"
    nmap.uv_map = source.uv_map
    nmap.location = (x, y)
    uv = nt.nodes.new("ShaderNodeUVMap")
    uv.uv_map = source.uv_map
    uv.location = (x - 400, y)
    nt.links.new(uv.outputs["UV"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    targets = [link.to_socket for link in bump.outputs["Normal"].links]
    for to in targets:
        nt.links.new(nmap.outputs["Normal"], to)
    shared = any(link.to_node not in (bump, *source.chain) for out in source.image_node.outputs for link in out.links)
    frame = None
    if keep_original:
        frame = nt.nodes.new("NodeFrame")
        frame.label = FRAME_LABEL
        bump.mute = True
        for n in [bump, *source.chain] + ([] if shared else [source.image_node]):
            n.parent = frame
    else:
        for n in source.chain:
            nt.nodes.remove(n)
        nt.nodes.remove(bump)
        if not shared:
            nt.nodes.remove(source.image_node)
    return Wired(material, source, image, [tex, nmap, uv], targets, frame)


def unwire(w: Wired):
    """Puts back a conversion made with `keep_original`: the Bump node feeds its targets again,
    the nodes and image made are removed."""
    nt = w.material.node_tree
    bump = w.source.bump
    for n in [bump, *w.source.chain, w.source.image_node]:
        if n.parent == w.frame:
            n.parent = None
    bump.mute = False
    for to in w.targets:
        nt.links.new(bump.outputs["Normal"], to)
    for n in [*w.added, *([w.frame] if w.frame else [])]:
        nt.nodes.remove(n)
    bpy.data.images.remove(w.image)


def convert_objects(objects, keep_original=True, filter="central", padding=16, float_buffer=True) -> Report:
    """Every Bump node in the objects' materials, each material converted once, on the first
    object (in the order given) that uses it."""
    import bumpbake

    start = time.perf_counter()
    report = Report()
    done = set()
    for obj in objects:
        if obj.type != "MESH":
            continue
        for slot in obj.material_slots:
            mat = slot.material
            if mat is None or mat.name in done:
                continue
            done.add(mat.name)
            sources, skipped = find(mat, obj)
            report.skipped += [(mat.name, b, why) for b, why in skipped]
            for src in sources:
                try:
                    image, ms = convert(obj, mat, src, filter, padding, float_buffer)
                except (ValueError, bumpbake.Error) as e:
                    report.skipped.append((mat.name, src.bump.name, str(e)))
                    continue
                report.wired.append(wire(mat, src, image, keep_original))
                report.converted.append((mat.name, src.bump.name, image.name, ms))
    report.seconds = time.perf_counter() - start
    return report
