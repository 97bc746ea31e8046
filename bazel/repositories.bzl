"""Makes a bumpbake binary built outside Bazel (cargo) available as `@<name>//:bumpbake`."""

def _bumpbake_local_binary_impl(rctx):
    path = rctx.os.environ.get("BUMPBAKE", "")
    if path:
        bin = rctx.path(path)
        if not bin.exists:
            fail("BUMPBAKE=%s: no such file (point it at a bumpbake binary, e.g. target/release/bumpbake)" % path)
    else:
        bin = rctx.which("bumpbake")
        if bin == None:
            fail("no bumpbake binary: set BUMPBAKE=/path/to/bumpbake (e.g. --repo_env=BUMPBAKE=...) " +
                 "or put bumpbake on PATH (cargo install --locked --path .)")
    # The binary's digest is part of every action's cache key: the same binary on two machines
    # shares their cache entries, a rebuilt one misses them.
    rctx.symlink(bin, "bumpbake")
    rctx.file("BUILD.bazel", 'exports_files(["bumpbake"])\n' +
                             'alias(name = "bin", actual = ":bumpbake", visibility = ["//visibility:public"])\n')

bumpbake_local_binary = repository_rule(
    implementation = _bumpbake_local_binary_impl,
    environ = ["BUMPBAKE", "PATH"],
    local = True,
    doc = "The bumpbake binary named by $BUMPBAKE, or the one on PATH, as `@<name>//:bumpbake`.",
)
