"""Relief extraction in Blender: a scan's relief lifted off its background, and put onto another object.

    import relief_snake.api as rs
    out = rs.extract_object(obj, step_height=1.0)          # relief vertices from the "Relief" group
    new = rs.apply_relief(out["relief"], target, location=(0, 0, 40))

extract_object() runs the native extraction (relief_snake_core.extract) on the object's mesh data
and creates <obj>_Relief (the relief's faces, float attribute `relief_height`, a UV map onto the
height map), <obj>_Base (the object with its relief moved onto the background under it) and an
image of the height map (32-bit float, saved as EXR when a folder is known). apply_relief() maps a
relief onto a target mesh's surface through the relief's flattening and offsets it along the
target's normals by its heights. Nothing is created unless everything succeeded. Coordinates:
extraction works in the scan's object space; apply_relief in world space.
"""

import json
import math
import os
import struct

import bpy

from . import mesh_io, placement

HEIGHT_ATTRIBUTE = "relief_height"
U_ATTRIBUTE = "relief_u"
V_ATTRIBUTE = "relief_v"
UV_MAP = "ReliefHeightMap"
META = "relief_snake_extraction"  # custom property on the relief object (JSON)


def _api():
    from . import api
    return api


def _error(message):
    return _api().EngineError(message)


def relief_vertices_from_group(obj, group_name):
    """Indices of the vertices in vertex group `group_name` (weight > 0)."""
    group = obj.vertex_groups.get(group_name)
    if group is None:
        raise _error("%r has no vertex group %r: segment the relief first (Relief Snake > Segment)"
                     % (obj.name, group_name))
    index = group.index
    out = []
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group == index and g.weight > 0:
                out.append(v.index)
                break
    if not out:
        raise _error("The vertex group %r of %r is empty: segment the relief first" % (group_name, obj.name))
    return out


def _remove(datablocks):
    """Removes what a failed call created (objects first, then their data)."""
    for block in datablocks:
        try:
            if isinstance(block, bpy.types.Object):
                bpy.data.objects.remove(block, do_unlink=True)
            elif isinstance(block, bpy.types.Mesh):
                bpy.data.meshes.remove(block)
            elif isinstance(block, bpy.types.Image):
                bpy.data.images.remove(block)
            elif isinstance(block, bpy.types.Texture):
                bpy.data.textures.remove(block)
        except ReferenceError:
            pass


def _replace_object(name, mesh, like, collection):
    """A new object `name` (an older one of that name is removed) with `like`'s transform."""
    old = bpy.data.objects.get(name)
    if old is not None:
        old_data = old.data
        bpy.data.objects.remove(old, do_unlink=True)
        if isinstance(old_data, bpy.types.Mesh) and old_data.users == 0:
            bpy.data.meshes.remove(old_data)
    ob = bpy.data.objects.new(name, mesh)
    if like is not None:
        ob.matrix_world = like.matrix_world.copy()
    collection.objects.link(ob)
    return ob


def _height_image(name, hm):
    """A float RGBA image of the height map: R = G = B = height, A = 1 inside the relief.
    Blender stores rows from the bottom; the engine's rows run from the top."""
    w, h = hm["width"], hm["height"]
    values = struct.unpack("<%df" % (w * h), hm["values"])
    mask = hm["mask"]
    pixels = [0.0] * (4 * w * h)
    for j in range(h):
        src = (h - 1 - j) * w
        dst = 4 * j * w
        for i in range(w):
            value = values[src + i]
            k = dst + 4 * i
            pixels[k] = pixels[k + 1] = pixels[k + 2] = value
            pixels[k + 3] = 1.0 if mask[src + i] else 0.0
    old = bpy.data.images.get(name)
    if old is not None:
        bpy.data.images.remove(old)
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(pixels)
    return image


def _image_uv(hm, u, v):
    """Height-map image coordinates (0..1, v up) of a point of the map's frame."""
    width = hm["width"] * hm["pixel_size"]
    height = hm["height"] * hm["pixel_size"]
    return (u - hm["u_left"]) / width, (v - (hm["v_top"] - height)) / height


def extract_object(obj, step_height, *, relief_vertices=None, group_name="Relief", pixel_size=0.0,
                   flatten="auto", image_dir=None, write=True):
    """Extract the relief of mesh object `obj`.

    relief_vertices: vertex indices of the relief (default: the vertex group `group_name`, as
    Segment writes it). step_height: h (> 0; it sets the width of the background fitted around the
    relief). pixel_size <= 0: half the average edge. flatten: 'auto', 'plane' or 'conformal'.
    image_dir: where to save <obj>_Height.exr (default: next to the saved .blend; not saved when
    the .blend is unsaved and no folder is given).

    Returns a dict: relief, base (objects), image, image_path (or None), and the engine's
    result (summary, ring_rms_residual, height_map metadata, ...). With write=False nothing is
    created and only the engine result is returned. Raises EngineError; on failure nothing of
    this call is left in the file.
    """
    api = _api()
    api._mesh_object(obj)
    if not step_height or step_height <= 0:
        raise _error("Set the step height h (> 0) first; Measure sets it from two vertices")
    if flatten not in ("auto", "plane", "conformal"):
        raise _error("flatten must be 'auto', 'plane' or 'conformal', not %r" % (flatten,))
    mesh_io.sync_edit_mode(obj)
    if relief_vertices is None:
        relief_vertices = relief_vertices_from_group(obj, group_name)
    vertices, triangles = mesh_io.read_buffers(obj.data)
    if not triangles:
        raise _error("The mesh %r has no faces" % obj.name)
    core = api.load_core()
    try:
        result = core.extract(vertices, triangles, [int(i) for i in relief_vertices], float(step_height),
                              pixel_size=float(pixel_size), flatten=flatten)
    except core.Error as exc:
        raise _error(str(exc)) from None
    if not write:
        return {"result": result}

    created = []
    try:
        out = _write_extraction(obj, result, sorted(set(int(i) for i in relief_vertices)), image_dir, created,
                                float(step_height))
    except Exception:
        _remove(created)
        raise
    out["result"] = result
    return out


def _write_extraction(obj, result, region, image_dir, created, step_height):
    collection = obj.users_collection[0] if obj.users_collection else bpy.context.scene.collection
    hm = result["height_map"]
    relief = result["relief"]
    src = obj.data

    # The relief: its faces over the scan's own vertex positions.
    index = relief["vertices"]
    coords = [tuple(src.vertices[i].co) for i in index]
    tris = relief["triangles"]
    faces = [tuple(tris[k:k + 3]) for k in range(0, len(tris), 3)]
    relief_mesh = bpy.data.meshes.new(obj.name + "_Relief")
    created.append(relief_mesh)
    relief_mesh.from_pydata(coords, [], faces)
    heights = relief["heights"]
    uv = relief["uv"]
    for name, values in ((HEIGHT_ATTRIBUTE, heights), (U_ATTRIBUTE, uv[0::2]), (V_ATTRIBUTE, uv[1::2])):
        attribute = relief_mesh.attributes.new(name, 'FLOAT', 'POINT')
        attribute.data.foreach_set("value", values)
    layer = relief_mesh.uv_layers.new(name=UV_MAP)
    loop_uv = []
    for loop in relief_mesh.loops:
        k = loop.vertex_index
        loop_uv.extend(_image_uv(hm, uv[2 * k], uv[2 * k + 1]))
    layer.data.foreach_set("uv", loop_uv)
    relief_mesh.update()

    # The base: the scan with only its relief vertices moved (everything else untouched).
    base_mesh = src.copy()
    base_mesh.name = obj.name + "_Base"
    created.append(base_mesh)
    base = result["base_positions"]
    for i in region:
        base_mesh.vertices[i].co = base[3 * i:3 * i + 3]
    base_mesh.update()

    image = _height_image(obj.name + "_Height", hm)
    created.append(image)
    image_path = None
    directory = image_dir or (bpy.path.abspath("//") if bpy.data.filepath else None)
    if directory:
        os.makedirs(directory, exist_ok=True)
        image_path = os.path.join(directory, obj.name + "_Height.exr")
        image.filepath_raw = image_path
        image.file_format = 'OPEN_EXR'
        image.use_half_precision = False
        tmp_path = image_path + ".partial.exr"
        image.filepath_raw = tmp_path
        image.save()
        os.replace(tmp_path, image_path)
        image.filepath_raw = image_path

    relief_ob = _replace_object(obj.name + "_Relief", relief_mesh, obj, collection)
    created.append(relief_ob)
    base_ob = _replace_object(obj.name + "_Base", base_mesh, obj, collection)
    created.append(base_ob)
    meta = {k: hm[k] for k in ("width", "height", "pixel_size", "u_left", "v_top", "min_height", "max_height")}
    meta.update(frame=hm["frame"], step_height=step_height, source=obj.name, image=image.name,
                image_path=image_path, ring_rms_residual=result["ring_rms_residual"])
    relief_ob[META] = json.dumps(meta)
    return {"relief": relief_ob, "base": base_ob, "image": image, "image_path": image_path}


# -- apply ----------------------------------------------------------------------------------

def _relief_data(relief):
    """(positions, triangles, heights, u, v) of a relief object made by extract_object."""
    if relief is None or getattr(relief, "type", None) != 'MESH':
        raise _error("Give the extracted relief (a mesh object made by Extract)")
    mesh = relief.data
    missing = [n for n in (HEIGHT_ATTRIBUTE, U_ATTRIBUTE, V_ATTRIBUTE) if n not in mesh.attributes]
    if missing:
        raise _error("%r is not an extracted relief (no %s attribute): run Extract on a scan first"
                     % (relief.name, missing[0]))
    n = len(mesh.vertices)
    values = {}
    for name in (HEIGHT_ATTRIBUTE, U_ATTRIBUTE, V_ATTRIBUTE):
        buf = [0.0] * n
        mesh.attributes[name].data.foreach_get("value", buf)
        values[name] = buf
    mesh.calc_loop_triangles()
    tris = [tuple(t.vertices) for t in mesh.loop_triangles]
    return values[HEIGHT_ATTRIBUTE], values[U_ATTRIBUTE], values[V_ATTRIBUTE], tris


class _Surface:
    """Nearest points and normals on a mesh object's evaluated surface, in world space."""

    def __init__(self, target):
        from mathutils.bvhtree import BVHTree
        depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated = target.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        try:
            mesh.calc_loop_triangles()
            if not mesh.loop_triangles:
                raise _error("The target %r has no faces" % target.name)
            mw = target.matrix_world
            verts = [mw @ v.co for v in mesh.vertices]
            tris = [tuple(t.vertices) for t in mesh.loop_triangles]
        finally:
            evaluated.to_mesh_clear()
        self.tree = BVHTree.FromPolygons(verts, tris)

    def nearest(self, point):
        location, normal, _, _ = self.tree.find_nearest(point)
        if location is None:
            raise _error("The target's surface could not be found near %s" % (tuple(point),))
        return location, normal.normalized()


def surface_hit(target, origin, direction):
    """Where the world ray (origin, direction) first meets mesh object `target`'s evaluated surface:
    the world point, or None if it misses (the ray is cast in the target's own coordinates, so
    any transform works)."""
    from mathutils import Matrix, Vector
    inverse = target.matrix_world.inverted_safe()
    local_origin, local_direction = placement.ray_to_local([tuple(r) for r in inverse], tuple(origin), tuple(direction))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    hit, location, _normal, _index = target.ray_cast(Vector(local_origin), Vector(local_direction),
                                                    depsgraph=depsgraph)
    if not hit:
        return None
    return Matrix(target.matrix_world) @ location


def apply_relief(relief, target, *, location=None, rotation=0.0, scale=1.0, name=None, rays=72, steps=48):
    """Put an extracted relief onto mesh object `target`: a new object lying on its surface.

    location: world point the relief's centre goes to (default: the 3D cursor), moved onto the
    target's surface. rotation (radians) turns the relief about the surface normal there; scale
    scales its footprint and heights. Each relief vertex is placed by walking from the centre
    along the target's surface in the direction and for the distance it has in the relief's
    flattening (geodesic polar coordinates, by marching `rays` directions in `steps` steps), then
    offset along the target's normal by its height. Returns the new object; raises EngineError.
    """
    from mathutils import Vector
    api = _api()
    api._mesh_object(target)
    if target == relief:
        raise _error("Pick a target other than the relief itself")
    if not scale or scale <= 0:
        raise _error("scale must be > 0")
    heights, us, vs, tris = _relief_data(relief)
    if not tris:
        raise _error("The relief %r has no faces" % relief.name)
    surface = _Surface(target)
    start = Vector(location) if location is not None else bpy.context.scene.cursor.location.copy()
    p0, n0 = surface.nearest(start)
    # Tangent frame at p0: the relief's u axis along the world X (or Y) projected, then rotated.
    t1, t2 = (Vector(a) for a in placement.tangent_frame(tuple(n0), rotation))

    n = len(heights)
    cu = 0.5 * (min(us) + max(us))
    cv = 0.5 * (min(vs) + max(vs))
    offsets = [((us[i] - cu) * scale, (vs[i] - cv) * scale) for i in range(n)]
    reach = max(math.hypot(a, b) for a, b in offsets) or 1.0
    step = reach / steps
    # March each ray along the surface: samples[k][s] is the point at arc length s * step.
    samples = []
    for k in range(rays):
        theta = 2 * math.pi * k / rays
        direction = math.cos(theta) * t1 + math.sin(theta) * t2
        point, normal = p0, n0
        ray = [p0]
        for _ in range(steps + 1):
            direction = (direction - direction.dot(normal) * normal).normalized()
            point, new_normal = surface.nearest(point + step * direction)
            if new_normal.dot(normal) < 0:
                new_normal = -new_normal
            normal = new_normal
            ray.append(point)
        samples.append(ray)

    positions = []
    for i in range(n):
        a, b = offsets[i]
        d = math.hypot(a, b)
        theta = math.atan2(b, a) % (2 * math.pi)
        fk = theta / (2 * math.pi) * rays
        k0 = int(fk) % rays
        k1 = (k0 + 1) % rays
        wk = fk - int(fk)
        fs = min(d / step, steps)
        s0 = int(fs)
        ws = fs - s0
        s1 = min(s0 + 1, steps + 1)

        def along(ray):
            return ray[s0].lerp(ray[s1], ws)

        guess = along(samples[k0]).lerp(along(samples[k1]), wk)
        foot, normal = surface.nearest(guess)
        if normal.dot(n0) < 0 and (foot - p0).length < reach:  # keep the outward side on closed targets
            normal = -normal
        positions.append(foot + heights[i] * scale * normal)

    mesh = bpy.data.meshes.new(name or (relief.name + "_Applied"))
    try:
        mesh.from_pydata([tuple(p) for p in positions], [], tris)
        attribute = mesh.attributes.new(HEIGHT_ATTRIBUTE, 'FLOAT', 'POINT')
        attribute.data.foreach_set("value", [h * scale for h in heights])
        mesh.update()
        collection = target.users_collection[0] if target.users_collection else bpy.context.scene.collection
        ob = bpy.data.objects.new(mesh.name, mesh)
        collection.objects.link(ob)
    except Exception:
        bpy.data.meshes.remove(mesh)
        raise
    return ob


def add_displace(relief, target, *, strength=1.0, uv_map=None):
    """The modifier alternative: a Displace modifier on `target` driven by the relief's height map
    (its image) through the target's UV map. Heights are in object units (strength 1, mid-level 0).
    Returns the modifier; raises EngineError if the target has no UV map or the relief no image."""
    api = _api()
    api._mesh_object(target)
    if relief is None or META not in relief.keys():
        raise _error("Give the extracted relief (a mesh object made by Extract)")
    meta = json.loads(relief[META])
    image = bpy.data.images.get(meta.get("image", ""))
    if image is None:
        raise _error("The relief's height map image %r is gone: run Extract again" % meta.get("image"))
    layers = target.data.uv_layers
    if not layers:
        raise _error("The target %r has no UV map: unwrap it first (or use the mesh placement)" % target.name)
    texture = bpy.data.textures.new(relief.name + "_Height", type='IMAGE')
    texture.image = image
    texture.extension = 'CLIP'
    modifier = target.modifiers.new(relief.name + "_Displace", 'DISPLACE')
    modifier.texture = texture
    modifier.texture_coords = 'UV'
    modifier.uv_layer = uv_map or layers.active.name
    modifier.mid_level = 0.0
    modifier.strength = strength
    return modifier
