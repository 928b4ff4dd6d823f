"""Extract and Apply inside Blender (run by run_tests.py in Blender 3.4 and bpy 4.2).

Uses the duck scan run_tests.py wrote (test_addon's configuration) with its true relief vertices
as the segmentation, so the checks do not depend on the snake."""

import math
import os
import shutil
import tempfile
import unittest

import bpy
from mathutils import Vector

import test_addon
from test_addon import clear_scene, make_scan_object, snapshot


def cfg():
    return test_addon._CFG


def api():
    import relief_snake.api as rs
    return rs


def write_relief_group(obj, name="Relief"):
    from relief_snake import mesh_io
    mesh_io.write_vertex_group(obj, name, cfg()["truth"]["relief_vertices"])


def attribute(ob, name):
    values = [0.0] * len(ob.data.vertices)
    ob.data.attributes[name].data.foreach_get("value", values)
    return values


class ExtractionTestCase(unittest.TestCase):
    def setUp(self):
        clear_scene()
        for image in list(bpy.data.images):
            bpy.data.images.remove(image)
        self.obj = make_scan_object()
        self.h = cfg()["truth"]["h"]
        bpy.context.scene.relief_snake.step_height = self.h
        self.tmp = tempfile.mkdtemp(prefix="relief-snake-extract-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def extract(self, **kw):
        return bpy.ops.mesh.relief_snake_extract(directory=self.tmp, **kw)


class Extract(ExtractionTestCase):
    def test_creates_relief_base_and_height_map(self):
        write_relief_group(self.obj)
        self.assertEqual(self.extract(), {'FINISHED'})
        relief = bpy.data.objects["Scan_Relief"]
        base = bpy.data.objects["Scan_Base"]
        heights = attribute(relief, "relief_height")
        # The duck's blended step rises from 0 to h: its top is at h, its foot near 0.
        self.assertAlmostEqual(max(heights), self.h, delta=0.05 * self.h)
        self.assertLess(min(heights), 0.1 * self.h)
        top = [x for x in heights if x > 0.5 * self.h]
        self.assertLess(sum(abs(x - self.h) for x in top if x > 0.9 * self.h) / len(top), 0.05 * self.h)
        # The base: every vertex outside the relief where it was, the relief's on the plane z = 0.
        region = set(cfg()["truth"]["relief_vertices"])
        src, dst = self.obj.data.vertices, base.data.vertices
        self.assertEqual(len(src), len(dst))
        outside = [i for i in range(len(src)) if i not in region and tuple(src[i].co) != tuple(dst[i].co)]
        self.assertEqual(outside, [])
        self.assertLess(max(abs(dst[i].co.z) for i in region), 0.05 * self.h)
        # The height map: a float image saved as EXR, and a UV map onto it.
        image = bpy.data.images["Scan_Height"]
        self.assertTrue(image.is_float)
        path = os.path.join(self.tmp, "Scan_Height.exr")
        self.assertTrue(os.path.isfile(path))
        with open(path, "rb") as f:
            self.assertEqual(f.read(4), b"\x76\x2f\x31\x01")
        self.assertIn("ReliefHeightMap", relief.data.uv_layers)
        self.assertIn("Last:", bpy.context.scene["relief_snake_last_extract"].replace("Relief Snake:", "Last:"))

    def test_headless_api_without_writing(self):
        out = api().extract_object(self.obj, self.h, relief_vertices=cfg()["truth"]["relief_vertices"],
                                   write=False)
        self.assertNotIn("Scan_Relief", bpy.data.objects)
        self.assertIn("summary", out["result"])
        self.assertEqual(out["result"]["height_map"]["frame"]["flattening"], "plane")

    def test_undo_removes_the_extraction(self):
        write_relief_group(self.obj)
        bpy.ops.ed.undo_push(message="setup")
        bpy.ops.ed.undo_push(message="before extract")
        self.assertEqual(bpy.ops.mesh.relief_snake_extract('EXEC_DEFAULT', True, directory=self.tmp),
                         {'FINISHED'})
        self.assertIn("Scan_Relief", bpy.data.objects)
        bpy.ops.ed.undo()
        self.assertNotIn("Scan_Relief", bpy.data.objects)
        self.assertNotIn("Scan_Base", bpy.data.objects)
        bpy.ops.ed.redo()
        self.assertIn("Scan_Relief", bpy.data.objects)


class ExtractErrors(ExtractionTestCase):
    def assertFailsCleanly(self, fragment, call):
        before = snapshot()
        images = len(bpy.data.images)
        meshes = len(bpy.data.meshes)
        with self.assertRaises((RuntimeError, api().EngineError)) as ctx:
            call()
        self.assertIn(fragment.lower(), str(ctx.exception).lower())
        self.assertEqual(snapshot(), before)
        self.assertEqual(len(bpy.data.images), images)
        self.assertEqual(len(bpy.data.meshes), meshes)

    def test_no_segmentation_yet(self):
        self.assertFailsCleanly("segment the relief first", self.extract)

    def test_no_step_height(self):
        write_relief_group(self.obj)
        bpy.context.scene.relief_snake.step_height = 0
        self.assertFailsCleanly("step height", self.extract)

    def test_region_without_background(self):
        every = list(range(len(self.obj.data.vertices)))
        self.assertFailsCleanly("no background",
                                lambda: api().extract_object(self.obj, self.h, relief_vertices=every))

    def test_indices_of_another_mesh(self):
        self.assertFailsCleanly("out of range", lambda: api().extract_object(
            self.obj, self.h, relief_vertices=[0, len(self.obj.data.vertices) + 10]))


class Apply(ExtractionTestCase):
    def setUp(self):
        super().setUp()
        write_relief_group(self.obj)
        self.assertEqual(self.extract(), {'FINISHED'})
        self.relief = bpy.data.objects["Scan_Relief"]

    def sphere(self, radius=40.0):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, segments=192, ring_count=96, location=(0, 0, 0))
        ob = bpy.context.active_object
        ob.name = "Target"
        return ob

    def test_heights_above_a_sphere_match_the_source(self):
        target = self.sphere()
        bpy.context.scene.cursor.location = (0.0, 0.0, 45.0)  # above the north pole
        for ob in bpy.context.selected_objects:
            ob.select_set(False)
        self.relief.select_set(True)
        target.select_set(True)
        bpy.context.view_layer.objects.active = self.relief
        self.assertEqual(bpy.ops.object.relief_snake_apply(), {'FINISHED'})
        applied = bpy.context.active_object
        self.assertNotEqual(applied, self.relief)
        # Heights above the sphere itself (|p| - R; its facets lie within 0.006 of it at this resolution).
        source = attribute(self.relief, "relief_height")
        worst, count = 0.0, 0
        for v, h in zip(applied.data.vertices, source):
            if h < 0.5 * self.h:
                continue
            measured = (applied.matrix_world @ v.co).length - 40.0
            worst = max(worst, abs(measured - h) / h)
            count += 1
        print("[ measured ] applied heights on a sphere: worst relative error %.4f over %d vertices" % (worst, count))
        self.assertGreater(count, 1000)
        self.assertLess(worst, 0.05)
        # The footprint keeps its size: the relief's uv extent is the arc length on the sphere.
        us = attribute(self.relief, "relief_u")
        i, j = us.index(min(us)), us.index(max(us))
        a = (applied.data.vertices[i].co).normalized()
        b = (applied.data.vertices[j].co).normalized()
        arc = 40.0 * a.angle(b)
        vs = attribute(self.relief, "relief_v")
        flat = math.hypot(us[j] - us[i], vs[j] - vs[i])
        self.assertAlmostEqual(arc, flat, delta=0.03 * flat)

    def test_scale_and_rotation(self):
        bpy.ops.mesh.primitive_plane_add(size=200, location=(0, 0, 0))
        target = bpy.context.active_object
        out = api().apply_relief(self.relief, target, location=(0, 0, 5), rotation=math.pi / 2, scale=2.0)
        heights = [v.co.z for v in out.data.vertices]
        self.assertAlmostEqual(max(heights), 2.0 * self.h, delta=0.1 * self.h)
        us, vs = attribute(self.relief, "relief_u"), attribute(self.relief, "relief_v")
        i, j = us.index(min(us)), us.index(max(us))
        d = out.data.vertices[j].co - out.data.vertices[i].co
        # A quarter turn about +z: the relief's (du, dv) lands at (-dv, du), twice as long.
        du, dv = 2.0 * (us[j] - us[i]), 2.0 * (vs[j] - vs[i])
        self.assertAlmostEqual(d.x, -dv, delta=0.03 * abs(du))
        self.assertAlmostEqual(d.y, du, delta=0.03 * abs(du))

    def test_click_placement_hits_the_target_where_the_ray_meets_it(self):
        from relief_snake import extraction
        target = self.sphere()
        target.location = (100.0, 0.0, 0.0)
        target.scale = (1.0, 1.0, 0.5)  # an ellipsoid: the ray is cast in the target's own coordinates
        bpy.context.view_layer.update()
        point = extraction.surface_hit(target, (100.0, 0.0, 500.0), (0.0, 0.0, -1.0))
        self.assertIsNotNone(point)
        self.assertAlmostEqual(point.x, 100.0, places=3)
        self.assertAlmostEqual(point.y, 0.0, places=3)
        self.assertAlmostEqual(point.z, 20.0, delta=0.02)  # the top of the squashed sphere
        self.assertIsNone(extraction.surface_hit(target, (0.0, 0.0, 500.0), (0.0, 0.0, -1.0)))  # beside it
        # What the modal pick does with the hit: apply at that location (the redo panel's state).
        for ob in bpy.context.selected_objects:
            ob.select_set(False)
        self.relief.select_set(True)
        target.select_set(True)
        bpy.context.view_layer.objects.active = self.relief
        self.assertEqual(bpy.ops.object.relief_snake_apply(placement='LOCATION', location=tuple(point)),
                         {'FINISHED'})
        applied = bpy.context.active_object
        centre = sum((applied.matrix_world @ v.co for v in applied.data.vertices), Vector()) / len(applied.data.vertices)
        self.assertLess(math.hypot(centre.x - 100.0, centre.y), 0.1 * max(applied.dimensions))
        self.assertGreater(centre.z, 19.0)

    def test_click_placement_needs_a_viewport(self):
        target = self.sphere()
        for ob in bpy.context.selected_objects:
            ob.select_set(False)
        self.relief.select_set(True)
        target.select_set(True)
        bpy.context.view_layer.objects.active = self.relief
        before = snapshot()
        with self.assertRaises(RuntimeError) as raised:  # background: no window to click in
            bpy.ops.object.relief_snake_apply('INVOKE_DEFAULT', placement='CLICK')
        self.assertIn("3D Viewport", str(raised.exception))
        self.assertEqual(snapshot(), before)

    def test_displace_modifier_alternative(self):
        bpy.ops.mesh.primitive_plane_add(size=100, location=(0, 0, 0))
        target = bpy.context.active_object
        modifier = api().add_displace(self.relief, target)
        self.assertEqual(modifier.type, 'DISPLACE')
        self.assertEqual(modifier.texture.image.name, "Scan_Height")
        self.assertEqual(modifier.texture_coords, 'UV')
        target.data.uv_layers.remove(target.data.uv_layers[0])
        with self.assertRaises(api().EngineError):
            api().add_displace(self.relief, target)

    def test_apply_errors(self):
        before = snapshot()
        with self.assertRaises(api().EngineError):
            api().apply_relief(self.obj, self.relief)  # the scan is not an extracted relief
        with self.assertRaises(RuntimeError):
            for ob in bpy.context.selected_objects:
                ob.select_set(False)
            bpy.ops.object.relief_snake_apply(relief="Scan_Relief")  # no target selected
        self.assertEqual(snapshot(), before)
