"""Headless example: detect every relief of a plate in one go with the Relief Snake add-on
(relief_snake.multi), write the candidates as vertex groups and outline curves, and render a PNG.

    build/make-scan --plate 2 --background cylinder --triangles 100000 --out /tmp/plate
    blender --background --factory-startup --python examples/detect_plate.py -- \
        --mesh /tmp/plate.ply --out DIR [--build-dir build]

The picture code (camera, materials, title, renderers) is examples/segment_scan.py's.
"""

import argparse
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import segment_scan  # noqa: E402  (the demo's picture code)

# One tint per relief (tan, green, blue, violet, ...), the outline orange as in the demo.
TINTS = [(0.85, 0.6, 0.4, 1.0), (0.45, 0.75, 0.45, 1.0), (0.45, 0.6, 0.9, 1.0), (0.75, 0.5, 0.85, 1.0),
         (0.9, 0.8, 0.35, 1.0), (0.4, 0.8, 0.8, 1.0)]


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--build-dir", default=os.path.join(segment_scan.ROOT, "build"))
    ap.add_argument("--resolution", type=int, nargs=2, default=(1400, 1000))
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    addon = segment_scan.enable_addon(os.path.abspath(args.build_dir))
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    scene = bpy.context.scene
    obj = segment_scan.import_scan(os.path.abspath(args.mesh))
    t0 = time.perf_counter()
    doc = addon.multi.detect_object(obj)
    seconds = time.perf_counter() - t0
    written = addon.multi.apply_candidates(obj, doc, range(len(doc["candidates"])))
    for k, c in enumerate(doc["candidates"]):
        print("detect_plate: candidate %d: %s, h %.3g, area %.4g, score %.2f, %d vertices"
              % (k + 1, c["status"], c["step_height"]["used"], c["detection"]["area"], c["detection"]["score"],
                 len(c["relief_vertices"])))
    print("detect_plate: %d candidates in %.2f s (engine %.2f s)" % (len(written), seconds,
                                                                     doc["timing"]["detect_seconds"]))
    mesh = obj.data
    mesh.materials.append(segment_scan._material("Scan", (0.7, 0.7, 0.7, 1.0)))
    owner = {}
    for k, c in enumerate(doc["candidates"]):
        mesh.materials.append(segment_scan._material("Relief%d" % (k + 1), TINTS[k % len(TINTS)]))
        for v in c["relief_vertices"]:
            owner.setdefault(v, k + 1)
    index = []
    for poly in mesh.polygons:
        ks = {owner.get(v, 0) for v in poly.vertices}
        index.append(ks.pop() if len(ks) == 1 else 0)
    mesh.polygons.foreach_set("material_index", index)
    mesh.update()
    contour_material = segment_scan._material("Contour", (1.0, 0.2, 0.0, 1.0))
    for name in written:
        curve = bpy.data.objects.get("%s_%sContour" % (obj.name, name))
        if curve is not None:
            curve.data.bevel_depth = max(obj.dimensions) * 0.003
            curve.show_in_front = True
            curve.data.materials.clear()
            curve.data.materials.append(contour_material)
    segment_scan.frame_camera(obj, scene)
    segment_scan.title(scene, "Relief Snake detect: %s - %d reliefs found without picks in %.1f s, outlines orange"
                       % (os.path.basename(args.mesh), len(written), doc["timing"]["detect_seconds"]))
    name = os.path.splitext(os.path.basename(args.mesh))[0]
    png = os.path.abspath(os.path.join(args.out, name + "-detect.png"))
    scene.render.image_settings.compression = 90  # a smaller file for docs/images
    engine = segment_scan.render(scene, png, args.resolution)
    if engine is None:
        raise SystemExit("detect_plate: no renderer worked headless")
    print("detect_plate: picture %s (%s)" % (png, engine))


if __name__ == "__main__":
    main()
