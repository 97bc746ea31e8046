"""glTF files whose tangents are MikkTSpace of the mesh as written, with Bump nodes turned into
normal maps and normal maps as KTX2 on request, checked by bumpbake's validator before the
export reports done: `bumpbake.export_gltf`, and the same in the stock glTF export dialog."""

from __future__ import annotations

import bpy

from . import bump

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


def exported_objects(context, selected_only: bool = False):
    objs = context.selected_objects if selected_only else context.view_layer.objects
    return [o for o in objs if o.type == "MESH" and o.visible_get()]


def set_last(line: str):
    bpy.context.window_manager["bumpbake_last_report"] = line


class BumpbakeExportSettings(bpy.types.PropertyGroup):
    enabled: bpy.props.BoolProperty(
        name="bumpbake: exact tangents",
        description="After export, replace the tangents with MikkTSpace of the written mesh and check the file",
        default=False,
    )
    bump_to_normal: bpy.props.BoolProperty(
        name="Bump nodes as normal maps",
        description="Bake each Bump node fed by an image into a normal map for the export (the scene is left as is)",
        default=True,
    )
    textures: bpy.props.EnumProperty(items=TEXTURES, default="png", name="Normal maps")


# The exporter finds its hooks by this class name.
class glTF2ExportUserExtension:
    """The stock exporter's hooks: before it gathers the scene, Bump nodes become normal maps
    (when asked); after it wrote the file, bumpbake finishes it and the scene is put back."""

    def __init__(self):
        self.converted = None

    def pre_export_hook(self, export_settings):
        settings = bpy.context.scene.bumpbake_export
        if settings.enabled and settings.bump_to_normal:
            selected = bool(export_settings.get("gltf_selected"))
            self.converted = bump.convert_objects(exported_objects(bpy.context, selected), keep_original=True)

    def post_export_hook(self, export_settings):
        settings = bpy.context.scene.bumpbake_export
        try:
            if not settings.enabled:
                return
            report = finish(export_settings["gltf_filepath"], settings.textures)
            line, error = summary(report)
            if self.converted is not None:
                line = f"{self.converted.line()}; {line}"
            set_last(line if error is None else f"{line}; {error}")
            log = export_settings.get("log")
            if log is not None:
                (log.error if error else log.info)(line if error is None else f"{line}; {error}")
        finally:
            if self.converted is not None:
                for w in reversed(self.converted.wired):
                    bump.unwire(w)
                self.converted = None


def draw_export(context, layout):
    settings = context.scene.bumpbake_export
    header, body = layout.panel("bumpbake_export", default_closed=False)
    header.use_property_split = False
    header.prop(settings, "enabled")
    if body:
        body.active = settings.enabled
        body.prop(settings, "bump_to_normal")
        body.prop(settings, "textures")
