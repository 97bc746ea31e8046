"""Bazel rules for bumpbake: tangents, normal maps, bakes and a validation test.

Every rule runs the bumpbake binary as a declared tool (`bumpbake`, default `@bumpbake//:bumpbake`,
made by `bumpbake_local_binary` in repositories.bzl). Actions see only their declared inputs (Bazel's
sandbox): a mesh's MTL, the images an MTL or glTF references and external `.bin` buffers must be
listed in `srcs`, in the same folders relative to the mesh as on disk. A file left out is missing in
the sandbox and bumpbake stops with exit 2, naming it. `list-inputs.sh` prints the list for a mesh.
"""

_TOOL = attr.label(
    default = "@bumpbake//:bumpbake",
    executable = True,
    cfg = "exec",
    allow_single_file = True,
    doc = "The bumpbake binary.",
)

_MESH = [".obj", ".gltf", ".glb"]

def _out(ctx, ext):
    name = ctx.attr.out or (ctx.label.name + ext)
    if not name.endswith(ext):
        fail("out must end in %s (one output file per target): %s" % (ext, name))
    return ctx.actions.declare_file(name)

def _run(ctx, verb, inputs, out, args):
    ctx.actions.run(
        executable = ctx.executable.bumpbake,
        arguments = [args],
        inputs = inputs,
        outputs = [out],
        mnemonic = "Bumpbake" + verb.capitalize(),
        progress_message = "bumpbake %s %s" % (verb, out.short_path),
    )
    return [DefaultInfo(files = depset([out]))]

def _tangents_impl(ctx):
    out = _out(ctx, ".glb")
    args = ctx.actions.args()
    args.add("tangents").add(ctx.file.mesh).add("-o", out).add("-q")
    if ctx.attr.all:
        args.add("--all")
    args.add_all(ctx.attr.options)
    return _run(ctx, "tangents", [ctx.file.mesh] + ctx.files.srcs, out, args)

bumpbake_tangents = rule(
    implementation = _tangents_impl,
    doc = "MikkTSpace tangents for an OBJ, glTF or GLB mesh, written as `<name>.glb`.",
    attrs = {
        "mesh": attr.label(allow_single_file = _MESH, mandatory = True),
        "srcs": attr.label_list(allow_files = True, doc = "Files the mesh references: MTL, images, .bin buffers."),
        "all": attr.bool(doc = "Tangents for every triangle primitive with UVs (`--all`)."),
        "options": attr.string_list(doc = "More `bumpbake tangents` options."),
        "out": attr.string(doc = "Output name (default `<name>.glb`)."),
        "bumpbake": _TOOL,
    },
)

def _bake_impl(ctx):
    out = _out(ctx, ".glb")
    args = ctx.actions.args()
    args.add("bake").add(ctx.file.mesh).add("-o", out).add("-q")
    inputs = [ctx.file.mesh] + ctx.files.srcs
    if ctx.file.height and ctx.file.normal:
        fail("give height or normal, not both")
    if ctx.file.height:
        args.add("--height", ctx.file.height)
        inputs.append(ctx.file.height)
    if ctx.file.normal:
        args.add("--normal", ctx.file.normal)
        inputs.append(ctx.file.normal)
    if ctx.attr.material:
        args.add("--material", ctx.attr.material)
    args.add_all(ctx.attr.options)
    return _run(ctx, "bake", inputs, out, args)

bumpbake_bake = rule(
    implementation = _bake_impl,
    doc = "Mesh + height or normal map -> a render-ready `<name>.glb` (`bumpbake bake`).",
    attrs = {
        "mesh": attr.label(allow_single_file = _MESH, mandatory = True),
        "srcs": attr.label_list(
            allow_files = True,
            doc = "Files the mesh references: MTL, its height map and textures, glTF images and buffers.",
        ),
        "height": attr.label(allow_single_file = True, doc = "A height map (`--height`)."),
        "normal": attr.label(allow_single_file = True, doc = "A normal map (`--normal`), e.g. a bumpbake_normalmap."),
        "material": attr.string(doc = "The material to bake (`--material`)."),
        "options": attr.string_list(doc = "More `bumpbake bake` options, e.g. [\"--strength\", \"4\"]."),
        "out": attr.string(doc = "Output name (default `<name>.glb`)."),
        "bumpbake": _TOOL,
    },
)

def _normalmap_impl(ctx):
    ext = "." + (ctx.attr.out.rpartition(".")[2] if ctx.attr.out else "png")
    out = _out(ctx, ext)
    args = ctx.actions.args()
    args.add("normalmap").add(ctx.file.height).add("-o", out).add("-q")
    args.add_all(ctx.attr.options)
    return _run(ctx, "normalmap", [ctx.file.height], out, args)

bumpbake_normalmap = rule(
    implementation = _normalmap_impl,
    doc = "Height map -> tangent-space normal map (`bumpbake normalmap`), `<name>.png` by default.",
    attrs = {
        "height": attr.label(allow_single_file = True, mandatory = True),
        "options": attr.string_list(doc = "More `bumpbake normalmap` options, e.g. [\"--strength\", \"4\", \"--bits\", \"16\"]."),
        "out": attr.string(doc = "Output name: .png or .exr (default `<name>.png`)."),
        "bumpbake": _TOOL,
    },
)

def _sh_quote(s):
    return "'" + s.replace("'", "'\\''") + "'"

def _validate_test_impl(ctx):
    words = ["validate", "--format", "junit"]
    if ctx.attr.strict:
        words.append("--strict")
    words += ctx.attr.options
    words += [f.short_path for f in ctx.files.srcs]
    script = ctx.actions.declare_file(ctx.label.name + ".sh")

    # The JUnit report goes where Bazel collects test XML; the human summary goes to the test log.
    ctx.actions.write(
        script,
        "#!/bin/sh\nexec %s %s > \"${XML_OUTPUT_FILE:-/dev/null}\"\n" % (
            _sh_quote(ctx.executable.bumpbake.short_path),
            " ".join([_sh_quote(w) for w in words]),
        ),
        is_executable = True,
    )
    runfiles = ctx.runfiles(files = [ctx.executable.bumpbake] + ctx.files.srcs + ctx.files.data)
    return [DefaultInfo(executable = script, runfiles = runfiles)]

bumpbake_validate_test = rule(
    implementation = _validate_test_impl,
    test = True,
    doc = "A test that runs `bumpbake validate` on `srcs` and fails on errors (and warnings if `strict`).",
    attrs = {
        "srcs": attr.label_list(allow_files = True, mandatory = True, doc = "Meshes and normal-map images to check."),
        "data": attr.label_list(allow_files = True, doc = "Files the meshes reference (MTL, images, buffers)."),
        "strict": attr.bool(default = True, doc = "Warnings fail too (`--strict`)."),
        "options": attr.string_list(doc = "More `bumpbake validate` options, e.g. [\"--allow\", \"TANGENT_UNUSED\"]."),
        "bumpbake": attr.label(
            default = "@bumpbake//:bumpbake",
            executable = True,
            cfg = "target",
            allow_single_file = True,
            doc = "The bumpbake binary.",
        ),
    },
)
