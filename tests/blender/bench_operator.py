"""End-to-end time of mesh.relief_snake_segment on a large synthetic scan, first click and
repeat click, split into Blender data transfer (selection + click order + foreach_get reads,
vertex group + curve writes), engine mesh intake and segmentation. Not part of the test suite
(it prints numbers, it asserts nothing); run in any of the Blenders:

    blender --background --factory-startup --python tests/blender/bench_operator.py -- [TRIANGLES] [--edit]
    .venv-bpy52/bin/python tests/blender/bench_operator.py [TRIANGLES] [--edit]   (RELIEF_SNAKE_MODULE_DIR=build/py313)

Uses $RELIEF_SNAKE_BUILD_DIR (default build/) for make-scan and relief_snake_core
($RELIEF_SNAKE_MODULE_DIR for the module if set). The scan is the duck with a blended step
(make-scan --step blended, seed 2). --edit runs the operator in Edit Mode (the usual way to
pick), otherwise in Object Mode. The repeat click finds the engine's Mesh in the add-on's
cache (same mesh data, same fingerprint): no intake, and the planarity is reused.
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


MODULE_DIR = os.environ.get("RELIEF_SNAKE_MODULE_DIR", BUILD)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    edit = "--edit" in argv
    argv = [a for a in argv if a and not a.startswith("--")]
    triangles = int(argv[0]) if argv else 300000
    sys.path[:0] = [MODULE_DIR, os.path.join(ROOT, "addon"), HERE]
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
    if edit:
        bpy.ops.object.mode_set(mode='EDIT')
    select_vertices(obj, truth["picks"])
    mesh.calc_loop_triangles()
    print("bench: Blender %s, %d vertices, %d triangles, %s Mode"
          % (bpy.app.version_string, len(mesh.vertices), len(mesh.loop_triangles), "Edit" if edit else "Object"))
    api = mod.api
    for label in ("first click", "repeat click"):
        _run_operator(api, obj, truth, label)
    sys.stdout.flush()
    os._exit(0)


def _run_operator(api, obj, truth, label):
    results = []
    real = api.run_engine

    def run_engine(*args, **kwargs):  # keep the operator's result for its read/intake/engine/write seconds
        results.append(real(*args, **kwargs))
        return results[-1]
    api.run_engine = run_engine
    try:
        t0 = time.perf_counter()
        ret = bpy.ops.mesh.relief_snake_segment('EXEC_DEFAULT', step_height=float(truth["h"]))
        total = time.perf_counter() - t0
    finally:
        api.run_engine = real
    r = results[-1]
    t = r["timing"]
    segmentation = t["engine"] - t["intake"]
    transfer = t["read"] + t["write"]
    other = total - t["engine"] - transfer
    obj = bpy.data.objects["Scan"]
    print("bench: %-12s %s total %.3f s = data transfer %.3f s (read %.3f, write %.3f; %.0f%% of the total) "
          "+ engine %.3f s (mesh intake %.3f, segmentation %.3f; mesh %s) + other %.3f s; status %s"
          % (label, ret, total, transfer, t["read"], t["write"], 100 * transfer / total, t["engine"], t["intake"],
             segmentation, "reused" if r["mesh_cached"] else "built", other, r.get("status")))



if __name__ == "__main__":
    main()
