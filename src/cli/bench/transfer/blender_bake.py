# Blender's selected-to-active normal bake of HIGH onto LOW, timed, for `bench transfer --blender`.
#
# Run with a Python that has the `bpy` module (Blender as a module, PyPI `bpy`):
#   python blender_bake.py LOW.glb HIGH.obj|.ply|.glb OUT.png SIZE REACH
# Prints one JSON line: stage times (s), the whole script's wall time and its peak resident memory.
# What a user of Blender does by hand: import both, Cycles on the CPU, one sample per texel, a
# tangent-space normal bake from the selected HIGH to the active LOW, cage extrusion and ray
# distance set to the bench's ray reach, the image saved as an 8-bit PNG.
import json
import os
import resource
import sys
import time

t0 = time.perf_counter()
import bpy  # noqa: E402

low_path, high_path, out_path, size, reach = sys.argv[1:6]
size, reach = int(size), float(reach)
stages = {}


def stage(name, t):
    stages[name] = round(time.perf_counter() - t, 4)
    return time.perf_counter()


bpy.ops.wm.read_factory_settings(use_empty=True)
t = stage("start", t0)


def import_mesh(path):
    before = set(bpy.data.objects)
    if path.endswith(".obj"):
        bpy.ops.wm.obj_import(filepath=path)
    elif path.endswith(".ply"):
        bpy.ops.wm.ply_import(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    return [o for o in bpy.data.objects if o not in before and o.type == "MESH"]


lows = import_mesh(low_path)
t = stage("import low", t)
highs = import_mesh(high_path)
t = stage("import high", t)

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.render.bake.use_selected_to_active = True
scene.render.bake.cage_extrusion = reach
scene.render.bake.max_ray_distance = 2 * reach
scene.render.bake.normal_space = "TANGENT"
scene.render.bake.margin = 4

image = bpy.data.images.new("baked", size, size, alpha=False, float_buffer=False)
image.colorspace_settings.name = "Non-Color"
low = lows[0]
if not low.data.materials:
    low.data.materials.append(bpy.data.materials.new("low"))
for mat in low.data.materials:
    mat.use_nodes = True
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node

bpy.ops.object.select_all(action="DESELECT")
for o in highs:
    o.select_set(True)
low.select_set(True)
bpy.context.view_layer.objects.active = low
t = stage("setup", t)
bpy.ops.object.bake(type="NORMAL")
t = stage("bake", t)
image.filepath_raw = os.path.abspath(out_path)
image.file_format = "PNG"
image.save()
t = stage("save", t)

print(
    json.dumps(
        {
            "wall_s": round(time.perf_counter() - t0, 4),
            "stages_s": stages,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e6,
            "blender": bpy.app.version_string,
        }
    )
)
