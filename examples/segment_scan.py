"""Headless example: import a scan, segment a relief with the Relief Snake add-on's API,
save a .blend and render a PNG of the contour on the mesh.

    blender --background --python examples/segment_scan.py -- \
        --mesh scan.ply --picks 12,40,77,103 --step-height 1.0 --out DIR
    # picks and h from make-scan's ground truth instead:
    blender --background --python examples/segment_scan.py -- --mesh duck.ply --truth duck.truth.json --out DIR
    # also extract the relief into EXTRACT (height map EXR) and put it on a sphere beside the scan:
    blender --background --python examples/segment_scan.py -- --mesh duck.ply --truth duck.truth.json \
        --out DIR --extract EXTRACT

Works in Blender 3.4 and 4.2+ (the PLY/OBJ import operators differ; both are handled).
Uses the installed add-on if Blender has one; otherwise the add-on from this source tree
and the module from build/ (override with --build-dir).
Rendering uses Workbench (it works headless through surfaceless EGL / software GL); if
that fails it falls back to Cycles on the CPU; if that fails too it draws a top view with
plain Python (a PNG writer below) and says so.
"""

import argparse
import json
import math
import os
import struct
import sys
import time
import zlib

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="segment_scan.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--mesh", required=True, help="scan to import (.ply or .obj)")
    p.add_argument("--picks", help="vertex indices around the relief, in order (comma separated)")
    p.add_argument("--step-height", type=float, help="h, the relief's step height")
    p.add_argument("--truth", help="make-scan truth JSON: picks, h, open, relief_side (and IoU report)")
    p.add_argument("--w-int", type=float, default=None, help="smoothness in (0, 1]; default: the engine chooses")
    p.add_argument("--open", action="store_true", help="open contour ending on the mesh boundary")
    p.add_argument("--side", choices=("auto", "left", "right"), default="auto",
                   help="relief side of the picks (open contours; auto: the engine decides and says which)")
    p.add_argument("--out", required=True, help="output directory for the .blend and the .png")
    p.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    p.add_argument("--resolution", type=int, nargs=2, default=(1280, 960))
    p.add_argument("--extract", metavar="DIR",
                   help="also extract the relief (height map EXR into DIR) and apply it to a sphere beside the "
                        "scan; the picture shows both")
    args = p.parse_args(argv)
    truth = None
    if args.truth:
        with open(args.truth) as f:
            truth = json.load(f)
        if args.picks is None:
            args.picks = ",".join(str(i) for i in truth["picks"])
        if args.step_height is None:
            args.step_height = float(truth["h"])
        if truth.get("open"):
            args.open = True
            args.side = truth.get("relief_side", args.side)
    if args.picks is None or args.step_height is None:
        p.error("give --picks and --step-height (or --truth)")
    args.picks = [int(s) for s in args.picks.replace(",", " ").split()]
    return args, truth


def enable_addon(build_dir):
    """The installed add-on if there is one, else this tree's (the module from build_dir)."""
    import addon_utils
    # Only names Blender knows: enabling a missing add-on prints a traceback even when it is caught.
    known = {m.__name__ for m in addon_utils.modules()}
    for name in ("relief_snake", "bl_ext.user_default.relief_snake"):
        if name not in known:
            continue
        try:
            mod = addon_utils.enable(name, default_set=True, handle_error=lambda exc: None)
        except Exception:
            mod = None
        if mod is not None:
            try:
                mod.api.load_core()
                return mod
            except Exception:
                addon_utils.disable(name)
    sys.path.insert(0, build_dir)  # example script, not the add-on: path tweaks are fine here
    sys.path.insert(0, os.path.join(ROOT, "addon"))
    mod = addon_utils.enable("relief_snake", default_set=True, handle_error=lambda exc: print(
        "segment_scan: enabling the add-on from this tree failed: %s" % exc))
    if mod is None:
        raise SystemExit("segment_scan: could not enable the relief_snake add-on")
    mod.api.load_core()  # fails with a clear message if the native module is missing
    return mod


def import_scan(path):
    """Import with whichever operator this Blender has; returns the new mesh object."""
    before = set(bpy.data.objects)
    ext = os.path.splitext(path)[1].lower()
    if ext == ".ply":
        # (hasattr(bpy.ops.wm, ...) is always true: bpy.ops resolves names lazily)
        if bpy.app.version >= (4, 0, 0):                # C++ importer
            bpy.ops.wm.ply_import(filepath=path)
        else:                                           # 3.x: the io_mesh_ply add-on
            bpy.ops.import_mesh.ply(filepath=path)
    elif ext == ".obj":
        # Keep the file's axes so picks/heights mean the same as in the file.
        if bpy.app.version >= (3, 2, 0):                # C++ importer
            bpy.ops.wm.obj_import(filepath=path, forward_axis='Y', up_axis='Z')
        else:
            bpy.ops.import_scene.obj(filepath=path, axis_forward='Y', axis_up='Z', split_mode='OFF')
    else:
        raise SystemExit("segment_scan: %s: only .ply and .obj are supported" % path)
    new = [o for o in bpy.data.objects if o not in before and o.type == 'MESH']
    if len(new) != 1:
        raise SystemExit("segment_scan: expected one mesh in %s, got %d" % (path, len(new)))
    return new[0]


def frame_camera(obj, scene, others=()):
    """An orthographic camera looking at the mesh obliquely (50 degrees off its average normal),
    so the relief's step shades against the background, framing `others` too; a sun from the side."""
    mesh = obj.data
    mw = obj.matrix_world
    from mathutils import Vector
    n = Vector((0, 0, 0))
    for poly in mesh.polygons:
        n += poly.normal * poly.area
    n = (mw.to_3x3() @ n).normalized() if n.length > 0 else Vector((0, 0, 1))
    from mathutils import Matrix
    side = n.orthogonal().normalized()
    view = (Matrix.Rotation(0.87, 3, side) @ n).normalized()  # tilt the view ~50 degrees
    corners = [ob.matrix_world @ Vector(c) for ob in (obj,) + tuple(others) for c in ob.bound_box]
    centre = sum(corners, Vector((0, 0, 0))) / len(corners)
    size = max((c - centre).length for c in corners) * 2
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.type = 'ORTHO'
    cam_data.ortho_scale = size * 1.05
    cam_data.clip_end = size * 10
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = centre + view * size * 2
    cam.rotation_euler = (-view).to_track_quat('-Z', 'Y').to_euler()
    scene.camera = cam
    light_data = bpy.data.lights.new("Sun", 'SUN')
    light = bpy.data.objects.new("Sun", light_data)
    scene.collection.objects.link(light)
    light.rotation_euler = (-(view + side).normalized()).to_track_quat('-Z', 'Y').to_euler()
    return cam


def mark_picks(obj, picks, radius):
    """A small blue ball on every pick (the vertices the outline started from)."""
    import bmesh
    mesh = bpy.data.meshes.new("Picks")
    bm = bmesh.new()
    for i in picks:
        co = obj.data.vertices[i].co
        m = bmesh.ops.create_icosphere(bm, subdivisions=2, radius=radius)
        bmesh.ops.translate(bm, verts=m["verts"], vec=co)
    bm.to_mesh(mesh)
    bm.free()
    ob = bpy.data.objects.new("Picks", mesh)
    bpy.context.scene.collection.objects.link(ob)
    ob.parent = obj
    ob.show_in_front = True
    mesh.materials.append(_material("Picks", (0.1, 0.35, 1.0, 1.0)))
    return ob


def title(scene, text):
    """The picture's title, stamped on the render."""
    r = scene.render
    for attr in dir(r):
        if attr.startswith("use_stamp_") and attr != "use_stamp_note":
            try:
                setattr(r, attr, False)
            except (AttributeError, TypeError):
                pass
    r.use_stamp = True
    r.use_stamp_note = True
    r.stamp_note_text = text
    r.stamp_font_size = 28


def _material(name, rgba):
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = rgba  # Workbench (color_type MATERIAL) uses the viewport colour
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = rgba
    return mat


def style(obj, curve, relief_vertices):
    """Grey mesh, relief faces tinted, a thick orange contour (materials: Workbench and Cycles)."""
    mesh = obj.data
    mesh.materials.append(_material("Scan", (0.7, 0.7, 0.7, 1.0)))
    mesh.materials.append(_material("Relief", (0.85, 0.6, 0.4, 1.0)))
    relief = set(relief_vertices)
    index = [1 if all(v in relief for v in poly.vertices) else 0 for poly in mesh.polygons]
    mesh.polygons.foreach_set("material_index", index)
    mesh.update()
    if curve is not None:
        curve.data.bevel_depth = max(obj.dimensions) * 0.004
        curve.show_in_front = True  # the contour lies at the foot of the step: keep it visible
        curve.data.materials.append(_material("Contour", (1.0, 0.2, 0.0, 1.0)))


def extract_and_apply(addon, obj, result, step_height, directory):
    """Extract the segmented relief (height map EXR into `directory`) and put it on a UV sphere
    beside the scan, on the sphere's top. Returns (sphere, applied relief, extraction summary)."""
    api = addon.api
    t0 = time.perf_counter()
    out = api.extract_object(obj, step_height, relief_vertices=result["relief_vertices"],
                             image_dir=os.path.abspath(directory))
    print("segment_scan: extraction: %s (%.2f s)" % (out["result"]["summary"], time.perf_counter() - t0))
    print("segment_scan: height map %s" % out["image_path"])
    for ob in (out["relief"], out["base"]):
        ob.hide_render = True  # they lie exactly on the scan
        ob.hide_set(True)
    from mathutils import Vector
    size = max(obj.dimensions)
    radius = 0.5 * size
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    right = max(c.x for c in corners)
    centre = Vector((right + 1.4 * radius, sum(c.y for c in corners) / 8, min(c.z for c in corners)))
    mesh = bpy.data.meshes.new("Sphere")
    import bmesh
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=192, v_segments=96, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    for poly in mesh.polygons:
        poly.use_smooth = True
    sphere = bpy.data.objects.new("Sphere", mesh)
    bpy.context.scene.collection.objects.link(sphere)
    sphere.location = centre
    bpy.context.view_layer.update()
    t0 = time.perf_counter()
    applied = api.apply_relief(out["relief"], sphere, location=centre + Vector((0, 0, 2 * radius)))
    print("segment_scan: applied the relief to the sphere: %d vertices in %.2f s"
          % (len(applied.data.vertices), time.perf_counter() - t0))
    mesh.materials.append(_material("Sphere", (0.55, 0.6, 0.7, 1.0)))
    applied.data.materials.append(_material("Applied", (0.85, 0.6, 0.4, 1.0)))
    for poly in applied.data.polygons:
        poly.use_smooth = True
    return sphere, applied, out["result"]["summary"]


def render(scene, path, resolution):
    """Workbench, else Cycles CPU; returns the engine used or None."""
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = path
    for engine in ('BLENDER_WORKBENCH', 'CYCLES'):
        try:
            scene.render.engine = engine
            if engine == 'BLENDER_WORKBENCH':
                shading = scene.display.shading
                shading.light = 'STUDIO'
                shading.color_type = 'MATERIAL'
            else:
                scene.cycles.device = 'CPU'
                scene.cycles.samples = 16
                scene.cycles.use_denoising = False  # Debian's build has no OpenImageDenoise
            bpy.ops.render.render(write_still=True)
            if os.path.exists(path) and os.path.getsize(path) > 0:
                return engine
        except Exception as exc:
            print("segment_scan: %s render failed: %s" % (engine, exc))
    return None


def draw_png(path, obj, contour, relief_vertices, size=800):
    """Fallback picture without any renderer: top view (object xy) of the mesh vertices
    (grey, relief tinted) and the contour (orange), written with zlib + struct."""
    vs = obj.data.vertices
    xs = [v.co.x for v in vs]
    ys = [v.co.y for v in vs]
    x0, y0 = min(xs), min(ys)
    s = (size - 1) / max(max(xs) - x0, max(ys) - y0, 1e-12)
    img = bytearray(b"\xff" * (size * size * 3))

    def put(x, y, rgb):
        i, j = int((x - x0) * s), size - 1 - int((y - y0) * s)
        if 0 <= i < size and 0 <= j < size:
            img[3 * (j * size + i):3 * (j * size + i) + 3] = bytes(rgb)

    relief = set(relief_vertices)
    for k, v in enumerate(vs):
        put(v.co.x, v.co.y, (215, 140, 90) if k in relief else (180, 180, 180))
    for a, b in zip(contour, contour[1:] + contour[:1]):
        steps = max(2, int(math.dist(a[:2], b[:2]) * s * 2))
        for t in range(steps):
            f = t / steps
            for dx in (-1, 0, 1):
                put(a[0] + f * (b[0] - a[0]) + dx / s, a[1] + f * (b[1] - a[1]), (255, 64, 0))
    raw = b"".join(b"\x00" + bytes(img[3 * size * r:3 * size * (r + 1)]) for r in range(size))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main():
    args, truth = parse_args()
    os.makedirs(args.out, exist_ok=True)
    addon = enable_addon(args.build_dir)
    # An empty scene: the example owns it.
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    scene = bpy.context.scene
    t0 = time.perf_counter()
    obj = import_scan(os.path.abspath(args.mesh))
    print("segment_scan: imported %s: %d vertices, %d faces in %.2f s"
          % (args.mesh, len(obj.data.vertices), len(obj.data.polygons), time.perf_counter() - t0))
    if truth is not None and truth.get("vertices") not in (None, len(obj.data.vertices)):
        print("segment_scan: warning: the importer changed the vertex count (%d, file has %d); picks may be off"
              % (len(obj.data.vertices), truth["vertices"]))

    result = addon.api.segment_object(obj, args.picks, args.step_height, w_int=args.w_int,
                                      open_contour=args.open, relief_side=args.side)
    summary = addon.summary  # bpy-free summaries
    print("Relief Snake: " + summary.result_summary(result))
    for line in summary.phase_lines(result):
        print("  " + line)
    if summary.status_warning(result):
        print("Relief Snake: warning: " + summary.status_warning(result))
    timing = result["timing"]
    print("segment_scan: read %.2f s, engine %.2f s, write %.2f s"
          % (timing["read"], timing["engine"], timing["write"]))
    if truth is not None and "relief_vertices" in truth:
        a, b = set(result["relief_vertices"]), set(truth["relief_vertices"])
        print("segment_scan: IoU against the ground truth %.3f" % (len(a & b) / max(1, len(a | b))))

    curve = bpy.data.objects.get(obj.name + "_ReliefContour")
    style(obj, curve, result["relief_vertices"])
    mark_picks(obj, args.picks, max(obj.dimensions) * 0.006)
    text = ("Relief Snake: %s - %d picks (blue), outline (orange), relief (tan), %d vertices"
            % (os.path.basename(args.mesh), len(args.picks), len(result["relief_vertices"])))
    others = ()
    if args.extract:
        sphere, applied, _ = extract_and_apply(addon, obj, result, args.step_height, args.extract)
        others = (sphere, applied)
        text += "; extracted and applied to a sphere (right)"
    frame_camera(obj, scene, others)
    title(scene, text)
    name = os.path.splitext(os.path.basename(args.mesh))[0]
    blend = os.path.abspath(os.path.join(args.out, name + ".blend"))
    png = os.path.abspath(os.path.join(args.out, name + ".png"))
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    engine = render(scene, png, args.resolution)
    if engine is None:
        draw_png(png, obj, result["contour"], result["relief_vertices"])
        engine = "no renderer worked headless: drew a top view with plain Python instead"
    print("segment_scan: saved %s" % blend)
    print("segment_scan: picture %s (%s)" % (png, engine))


if __name__ == "__main__":
    main()
