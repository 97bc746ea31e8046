"""bumpbake for Blender: glTF files whose tangents are MikkTSpace of the mesh as written, with
normal maps as KTX2 on request, checked by bumpbake's validator before the export reports done.

Blender's glTF exporter writes tangents that are not MikkTSpace of the triangles it writes (on
Suzanne up to 25° off), so a renderer that recomputes them, or a map baked against MikkTSpace,
shades seams. This add-on runs bumpbake on the file the exporter wrote: `bumpbake.export_gltf`,
and a checkbox in the stock glTF export dialog that does the same after any export.
"""

from __future__ import annotations

import os
from typing import ClassVar

import bpy
from bpy.props import BoolProperty, EnumProperty, StringProperty

TEXTURES = (
    ("png", "As exported", "Keep the exporter's images (PNG/JPEG)"),
    ("ktx2", "KTX2", "Normal maps as KTX2 (Basis Universal), mips made from the normals, roughness widened to match"),
)


def finish(path: str, textures: str = "png") -> dict:
    """Makes the glTF at `path` exact in place: MikkTSpace tangents of the written mesh where a
    material needs them (the exporter's replaced), KTX2 normal maps when asked; returns
    bumpbake's validate report."""
    import bumpbake

    bumpbake.tangents_file(path, path, overwrite=True)
    if textures == "ktx2":
        bumpbake.textures(path, path)
    return bumpbake.validate(path)


def summary(report: dict) -> tuple[str, str | None]:
    """One line for Blender's report, and the first error's finding (None when there is none)."""
    s = report["summary"]
    line = f"bumpbake validate: {s['errors']} error(s), {s['warnings']} warning(s), {s['checks']} checks"
    for f in report.get("files", []):
        for subject in f.get("subjects", []):
            for finding in subject.get("findings", []):
                if finding.get("severity") == "error":
                    return line, f"{finding['code']}: {finding['message']}"
    return line, None


class BUMPBAKE_OT_export_gltf(bpy.types.Operator):
    """Export glTF with Blender's exporter, then give it MikkTSpace-exact tangents and check it"""

    bl_idname = "bumpbake.export_gltf"
    bl_label = "Export glTF (bumpbake)"
    bl_options: ClassVar[set[str]] = {"REGISTER"}

    filepath: StringProperty(subtype="FILE_PATH", description="The .glb or .gltf to write")
    textures: EnumProperty(items=TEXTURES, default="png", description="How normal maps are written")

    def execute(self, context):
        path = bpy.path.abspath(self.filepath)
        if not path.lower().endswith((".glb", ".gltf")):
            self.report({"ERROR"}, f"{path}: give a .glb or .gltf path")
            return {"CANCELLED"}
        fmt = "GLB" if path.lower().endswith(".glb") else "GLTF_SEPARATE"
        result = bpy.ops.export_scene.gltf(filepath=path, export_format=fmt, export_tangents=True)
        if "FINISHED" not in result:
            return {"CANCELLED"}
        return report_finish(self, path, self.textures)

    def invoke(self, context, event):
        if not self.filepath:
            blend = bpy.data.filepath
            self.filepath = os.path.splitext(blend)[0] + ".glb" if blend else "untitled.glb"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}


def report_finish(op, path: str, textures: str):
    import bumpbake

    try:
        report = finish(path, textures)
    except bumpbake.Error as e:
        op.report({"ERROR"}, f"bumpbake: {e}")
        return {"CANCELLED"}
    line, error = summary(report)
    bpy.context.window_manager["bumpbake_last_report"] = line if error is None else f"{line}; {error}"
    if error is not None:
        op.report({"ERROR"}, f"{line}; {error}")
        return {"CANCELLED"}
    op.report({"INFO"}, line)
    return {"FINISHED"}


class BumpbakeExportSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="bumpbake: exact tangents",
        description="After export, replace the tangents with MikkTSpace of the written mesh and check the file",
        default=False,
    )
    textures: EnumProperty(items=TEXTURES, default="png", name="Normal maps")


# The exporter finds its hooks by this class name.
class glTF2ExportUserExtension:
    """The stock exporter's hook: after it wrote the file, bumpbake finishes it when the
    checkbox is on."""

    def post_export_hook(self, export_settings):
        settings = bpy.context.scene.bumpbake_export
        if not settings.enabled:
            return
        path = export_settings["gltf_filepath"]
        report = finish(path, settings.textures)
        line, error = summary(report)
        bpy.context.window_manager["bumpbake_last_report"] = line if error is None else f"{line}; {error}"
        log = export_settings.get("log")
        if log is not None:
            (log.error if error else log.info)(line if error is None else f"{line}; {error}")


def draw_export(context, layout):
    settings = context.scene.bumpbake_export
    header, body = layout.panel("bumpbake_export", default_closed=False)
    header.use_property_split = False
    header.prop(settings, "enabled")
    if body:
        body.active = settings.enabled
        body.prop(settings, "textures")


class BUMPBAKE_PT_material(bpy.types.Panel):
    bl_label = "bumpbake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    def draw(self, context):
        self.layout.operator(BUMPBAKE_OT_export_gltf.bl_idname, icon="EXPORT")
        last = context.window_manager.get("bumpbake_last_report")
        if last:
            self.layout.label(text=last)


CLASSES = (BUMPBAKE_OT_export_gltf, BumpbakeExportSettings, BUMPBAKE_PT_material)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)
    bpy.types.Scene.bumpbake_export = bpy.props.PointerProperty(type=BumpbakeExportSettings)
    try:
        import io_scene_gltf2

        io_scene_gltf2.exporter_extension_layout_draw["bumpbake"] = draw_export
    except ImportError:
        pass


def unregister():
    try:
        import io_scene_gltf2

        io_scene_gltf2.exporter_extension_layout_draw.pop("bumpbake", None)
    except ImportError:
        pass
    del bpy.types.Scene.bumpbake_export
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
