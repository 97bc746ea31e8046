"""bumpbake for Blender: Bump nodes turned into normal maps exactly as Cycles shades them, glTF
files whose tangents are MikkTSpace of the mesh as written, and selected-to-active normal bakes,
all on the bumpbake library (its Python package is this extension's wheel).

- `bumpbake.bump_to_normal`: Bump nodes fed by an Image Texture become normal maps baked through
  the object's mesh, wired through a Normal Map node; the Bump chain is kept, muted, in a frame.
- `bumpbake.export_gltf`: Blender's glTF exporter, with Bump nodes as normal maps for the file,
  then MikkTSpace tangents of the written mesh, KTX2 on request and bumpbake's validation; the
  same is a panel in the stock glTF export dialog.
- `bumpbake.bake_selected_to_active`: the selected meshes baked onto the active one's UVs.
"""

from __future__ import annotations

import os
from typing import ClassVar

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from . import bump, export, selected
from .export import glTF2ExportUserExtension  # noqa: F401  (the exporter looks for it here)

FILTERS = (
    ("central", "Central", "Central differences: closest to how Cycles' Bump node differentiates"),
    ("sobel", "Sobel", "Central differences smoothed across: less noise from noisy heights"),
    ("scharr", "Scharr", "Like Sobel, more even in every direction"),
)


class BUMPBAKE_OT_bump_to_normal(bpy.types.Operator):
    """Turn Bump nodes fed by an image into normal maps baked through each selected object's mesh"""

    bl_idname = "bumpbake.bump_to_normal"
    bl_label = "Bump Nodes to Normal Maps"
    bl_options: ClassVar[set[str]] = {"REGISTER", "UNDO"}

    keep_original: BoolProperty(
        name="Keep Bump nodes",
        description="Keep each Bump node and its image in a frame, muted, so the step can be undone by hand",
        default=True,
    )
    filter: EnumProperty(items=FILTERS, default="central", name="Derivative")
    padding: IntProperty(name="Padding", description="Texels filled around UV islands", default=16, min=0, max=256)

    @classmethod
    def poll(cls, context):
        return any(o.type == "MESH" for o in context.selected_objects)

    def execute(self, context):
        objects = [o for o in context.selected_objects if o.type == "MESH"]
        active = context.active_object
        if active in objects:
            objects.remove(active)
            objects.insert(0, active)
        report = bump.convert_objects(objects, self.keep_original, self.filter, self.padding)
        line = report.line()
        export.set_last(line)
        if not report.converted and report.skipped:
            self.report({"WARNING"}, line)
        else:
            self.report({"INFO"}, line)
        return {"FINISHED"}


class BUMPBAKE_OT_export_gltf(bpy.types.Operator):
    """Export glTF with Blender's exporter, Bump nodes as normal maps, MikkTSpace-exact tangents, checked"""

    bl_idname = "bumpbake.export_gltf"
    bl_label = "Export glTF (bumpbake)"
    bl_options: ClassVar[set[str]] = {"REGISTER"}

    filepath: StringProperty(subtype="FILE_PATH", description="The .glb or .gltf to write")
    textures: EnumProperty(items=export.TEXTURES, default="png", description="How normal maps are written")
    bump_to_normal: BoolProperty(
        name="Bump nodes as normal maps",
        description="Bake each Bump node fed by an image into a normal map for the file (the scene is left as it was)",
        default=True,
    )
    use_selection: BoolProperty(name="Selected only", default=False)

    def execute(self, context):
        path = bpy.path.abspath(self.filepath)
        if not path.lower().endswith((".glb", ".gltf")):
            self.report({"ERROR"}, f"{path}: give a .glb or .gltf path")
            return {"CANCELLED"}
        converted = None
        if self.bump_to_normal:
            objects = export.exported_objects(context, self.use_selection)
            converted = bump.convert_objects(objects, keep_original=True)
        try:
            fmt = "GLB" if path.lower().endswith(".glb") else "GLTF_SEPARATE"
            result = bpy.ops.export_scene.gltf(
                filepath=path, export_format=fmt, export_tangents=True, use_selection=self.use_selection
            )
        finally:
            if converted is not None:
                for w in reversed(converted.wired):
                    bump.unwire(w)
        if "FINISHED" not in result:
            return {"CANCELLED"}
        return self.finish(path, converted)

    def finish(self, path, converted):
        import bumpbake

        try:
            report = export.finish(path, self.textures)
        except bumpbake.Error as e:
            self.report({"ERROR"}, f"bumpbake: {e}")
            return {"CANCELLED"}
        line, error = export.summary(report)
        if converted is not None:
            line = f"{converted.line()}; {line}"
        export.set_last(line if error is None else f"{line}; {error}")
        if error is not None:
            self.report({"ERROR"}, f"{line}; {error}")
            return {"CANCELLED"}
        self.report({"INFO"}, line)
        return {"FINISHED"}

    def invoke(self, context, event):
        if not self.filepath:
            blend = bpy.data.filepath
            self.filepath = os.path.splitext(blend)[0] + ".glb" if blend else "untitled.glb"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}


class BUMPBAKE_OT_bake_selected_to_active(bpy.types.Operator):
    """Bake the selected meshes' surface onto the active mesh's UVs as a tangent-space normal map (bumpbake)"""

    bl_idname = "bumpbake.bake_selected_to_active"
    bl_label = "Bake Selected to Active (bumpbake)"
    bl_options: ClassVar[set[str]] = {"REGISTER", "UNDO"}

    size: IntProperty(name="Size", description="Width and height of the map", default=1024, min=1, max=8192)
    extrusion: FloatProperty(
        name="Extrusion", description="How far outside the active mesh rays start", default=-1.0, subtype="DISTANCE"
    )
    max_ray_distance: FloatProperty(
        name="Max Ray Distance",
        description="How far rays reach from where they start (0: no limit)",
        default=-1.0,
        subtype="DISTANCE",
    )
    samples: IntProperty(name="Samples", description="Rays per texel along each axis", default=1, min=1, max=8)
    padding: IntProperty(name="Margin", description="Texels filled around UV islands", default=-1, min=-1, max=256)

    @classmethod
    def poll(cls, context):
        a = context.active_object
        return a is not None and a.type == "MESH" and any(o != a and o.type == "MESH" for o in context.selected_objects)

    def defaults_from_scene(self, context):
        """Blender's own bake settings where the operator was not told otherwise."""
        b = context.scene.render.bake
        if self.extrusion < 0:
            self.extrusion = b.cage_extrusion
        if self.max_ray_distance < 0:
            self.max_ray_distance = b.max_ray_distance
        if self.padding < 0:
            self.padding = b.margin

    def execute(self, context):
        self.defaults_from_scene(context)
        active = context.active_object
        highs = [o for o in context.selected_objects if o != active and o.type == "MESH"]
        import bumpbake

        try:
            result = selected.bake(
                active, highs, self.size, self.extrusion, self.max_ray_distance, self.samples, padding=self.padding
            )
        except (ValueError, bumpbake.Error) as e:
            self.report({"ERROR"}, f"bumpbake: {e}")
            return {"CANCELLED"}
        selected.wire_into(active, result.image)
        c = result.report.get("transfer", {}).get("counts", {})
        line = (
            f"bumpbake: {len(highs)} mesh(es) baked onto {active.name} at {self.size}² in {result.seconds:.2f} s"
            f" ({c.get('missed', 0)} texel samples missed)"
        )
        export.set_last(line)
        self.report({"INFO"}, line)
        return {"FINISHED"}


def draw_operators(layout, context):
    col = layout.column(align=True)
    col.operator(BUMPBAKE_OT_bump_to_normal.bl_idname, icon="NODE_MATERIAL")
    col.operator(BUMPBAKE_OT_export_gltf.bl_idname, icon="EXPORT")
    col.operator(BUMPBAKE_OT_bake_selected_to_active.bl_idname, icon="RENDER_STILL")
    last = context.window_manager.get("bumpbake_last_report")
    if last:
        box = layout.box()
        for part in str(last).split("; "):
            box.label(text=part)


class BUMPBAKE_PT_material(bpy.types.Panel):
    bl_label = "bumpbake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    def draw(self, context):
        draw_operators(self.layout, context)


class BUMPBAKE_PT_bake(bpy.types.Panel):
    bl_label = "bumpbake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_parent_id = "CYCLES_RENDER_PT_bake"

    def draw(self, context):
        draw_operators(self.layout, context)


CLASSES = (
    BUMPBAKE_OT_bump_to_normal,
    BUMPBAKE_OT_export_gltf,
    BUMPBAKE_OT_bake_selected_to_active,
    export.BumpbakeExportSettings,
    BUMPBAKE_PT_material,
)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    # Render > Bake is Cycles' panel: ours goes inside it when Cycles is there.
    if hasattr(bpy.types, "CYCLES_RENDER_PT_bake"):
        bpy.utils.register_class(BUMPBAKE_PT_bake)
    bpy.types.Scene.bumpbake_export = bpy.props.PointerProperty(type=export.BumpbakeExportSettings)
    try:
        import io_scene_gltf2

        io_scene_gltf2.exporter_extension_layout_draw["bumpbake"] = export.draw_export
    except ImportError:
        pass


def unregister():
    try:
        import io_scene_gltf2

        io_scene_gltf2.exporter_extension_layout_draw.pop("bumpbake", None)
    except ImportError:
        pass
    del bpy.types.Scene.bumpbake_export
    if BUMPBAKE_PT_bake.is_registered:
        bpy.utils.unregister_class(BUMPBAKE_PT_bake)
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
