"""End-to-end time of mesh.relief_snake_segment on a large synthetic scan, split into
Blender data transfer (selection + foreach_get reads, vertex group + curve writes) and
engine time. Not part of the test suite; run in either Blender:

    blender --background --factory-startup --python tests/blender/bench_operator.py -- [TRIANGLES]
    .venv-bpy/bin/python tests/blender/bench_operator.py [TRIANGLES]

Uses $RELIEF_SNAKE_BUILD_DIR (default build/) for make-scan and relief_snake_core.
The scan is the duck with a blended step (make-scan --step blended, seed 2). "engine" is the
module call: building the engine's mesh from the buffers (mesh intake) plus the segmentation.
"""

import os
import subprocess
import sys
import tempfile
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
BUILD = os.environ.get("RELIEF_SNAKE_BUILD_DIR", os.path.join(ROOT, "build"))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    transfer_only = "--transfer-only" in argv  # skip the engine (e.g. while it is unfinished)
    argv = [a for a in argv if a != "--transfer-only"]
    triangles = int(argv[0]) if argv else 300000
    sys.path[:0] = [BUILD, os.path.join(ROOT, "addon"), HERE]
    import addon_utils
    import json
    import plyio
    from test_addon import select_vertices
    mod = addon_utils.enable("relief_snake", default_set=True)
    prefix = os.path.join(tempfile.mkdtemp(prefix="relief-snake-bench-"), "duck")
    subprocess.run([os.path.join(BUILD, "make-scan"), "--shape", "duck", "--background", "plane",
                    "--triangles", str(triangles), "--step", "blended", "--seed", "2", "--out", prefix], check=True,
                   stdout=subprocess.DEVNULL)
    truth = json.load(open(prefix + ".truth.json"))
    verts, faces = plyio.read_ply(prefix + ".ply")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    mesh = bpy.data.meshes.new("Scan")
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new("Scan", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    select_vertices(obj, truth["picks"])

    want = set(truth["relief_vertices"])
    got = want
    if transfer_only:
        print("bench: Blender %s, %d vertices, %d faces (transfer only, no engine run)"
              % (bpy.app.version_string, len(mesh.vertices), len(mesh.polygons)))
    else:
        got = _run_operator(obj, truth, mesh)
    api, mesh_io = mod.api, mod.mesh_io
    contour = [tuple(p) for line in truth["boundary"] for p in line] if isinstance(truth["boundary"][0][0], list) \
        else [tuple(p) for p in truth["boundary"]]
    for name, fn in (("selection + click order", lambda: api.selected_picks(obj)),
                     ("foreach_get vertices + loop triangles", lambda: mesh_io.read_buffers(obj.data)),
                     ("vertex group write (%d vertices)" % len(got),
                      lambda: mesh_io.write_vertex_group(obj, "Relief", sorted(got))),
                     ("curve write (%d points)" % len(contour), lambda: mesh_io.write_curve(obj, contour, True))):
        best = min(_timed(fn) for _ in range(3))
        print("bench:   %-40s %.3f s" % (name, best))
    sys.stdout.flush()
    os._exit(0)


def _run_operator(obj, truth, mesh):
    import relief_snake.api as api
    results = []
    real_run = api.run

    def run(*args, **kwargs):  # keep the operator's result for its exact read/engine/write seconds
        results.append(real_run(*args, **kwargs))
        return results[-1]
    api.run = run
    try:
        t0 = time.perf_counter()
        ret = bpy.ops.mesh.relief_snake_segment('EXEC_DEFAULT', step_height=float(truth["h"]))
        total = time.perf_counter() - t0
    finally:
        api.run = real_run
    s = bpy.context.scene.relief_snake
    gi = obj.vertex_groups["Relief"].index
    got = {v.index for v in obj.data.vertices if any(g.group == gi for g in v.groups)}
    want = set(truth["relief_vertices"])
    print("bench: Blender %s, %d vertices, %d triangles: %s in %.2f s"
          % (bpy.app.version_string, len(mesh.vertices), len(mesh.loop_triangles), ret, total))
    print("bench: " + s.last_summary)
    for line in s.last_phases.splitlines():
        print("bench:   " + line)
    score = len(got & want) / max(1, len(got | want))
    print("bench: IoU %.3f" % score)
    if results:
        t = results[-1]["timing"]
        segmentation = sum(p["seconds"] for p in results[-1]["phases"])
        intake = results[-1]["seconds"] - segmentation
        print("bench: SUMMARY total %.2f s = engine %.2f s (mesh intake %.2f s, segmentation %.2f s) + data transfer "
              "%.2f s (read %.2f s, write %.2f s) + other %.2f s; status %s; IoU %.3f"
              % (total, t["engine"], intake, segmentation, t["read"] + t["write"], t["read"], t["write"],
                 total - t["engine"] - t["read"] - t["write"], results[-1].get("status"), score))
    return got


def _timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


if __name__ == "__main__":
    main()
