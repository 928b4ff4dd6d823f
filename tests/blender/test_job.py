"""bpy-free tests of addon/relief_snake/job.py: the worker thread, its cancel flag and progress
snapshot, the mesh fingerprint and cache, and the engine-contract fallbacks. The engine here is
a small stand-in written for these tests (the real one runs in test_addon.py and tests/blender/ui/)."""

import time
import unittest
from array import array

import _addon_path  # noqa: F401
import job  # noqa: E402


class StandInCore:
    """Enough of relief_snake_core's surface for job.py: Mesh(v, t).segment(...), Error, Cancelled."""

    class Error(ValueError):
        pass

    class Cancelled(Exception):
        pass

    def __init__(self, steps=50, step_seconds=0.01, fail=None, supports_auto=True, status="converged"):
        self.steps, self.step_seconds, self.fail = steps, step_seconds, fail
        self.supports_auto, self.status = supports_auto, status
        self.meshes_built = 0
        self.calls = []
        core = self

        class Mesh:
            def __init__(self, vertices, triangles):
                core.meshes_built += 1

            def segment(self, picks, step_height, progress=None, **kw):
                core.calls.append((step_height, dict(kw)))
                if (step_height is None or kw.get("w_int") is None) and not core.supports_auto:
                    raise TypeError("segment(): incompatible function arguments. The following argument "
                                    "types are supported: ...")
                if core.fail:
                    raise core.fail
                for i in range(core.steps):
                    time.sleep(core.step_seconds)
                    if progress is not None and progress("coarse", i, 10 + i, [(0, 0, 0)] * 3) is False:
                        raise core.Cancelled("cancelled")
                return {"status": core.status, "closed": True, "contour": [(0, 0, 0)] * 4,
                        "relief_vertices": [0, 1], "phases": [], "seconds": 0.1}

        self.Mesh = Mesh


def request(z=0.0, key="Scan"):
    v = array('f', [0, 0, z, 1, 0, 0, 0, 1, 0])
    return job.Request(v, array('i', [0, 1, 2]), [0, 1, 2], 1.0, {"w_int": 0.25}, key=key)


class Fingerprint(unittest.TestCase):
    def test_any_change_changes_it(self):
        self.assertEqual(request().digest, request().digest)
        self.assertNotEqual(request().digest, request(z=1e-6).digest)
        a = array('i', [0, 1, 2])
        b = array('i', [0, 2, 1])
        v = array('f', [0] * 9)
        self.assertNotEqual(job.fingerprint(v, a), job.fingerprint(v, b))


class MeshCacheAndEngine(unittest.TestCase):
    def test_second_run_on_the_same_mesh_reuses_the_engine_mesh(self):
        core, cache = StandInCore(steps=1), job.MeshCache()
        first = job.run_engine(core, request(), cache=cache)
        second = job.run_engine(core, request(), cache=cache)
        self.assertEqual(core.meshes_built, 1)
        self.assertFalse(first["mesh_cached"])
        self.assertTrue(second["mesh_cached"])
        job.run_engine(core, request(z=0.5), cache=cache)  # edited: rebuilt
        self.assertEqual(core.meshes_built, 2)
        for key in ("read", "intake", "engine", "write"):
            self.assertIn(key, second["timing"])

    def test_cache_is_bounded(self):
        core, cache = StandInCore(steps=1), job.MeshCache(size=2)
        for k in ("a", "b", "c"):
            job.run_engine(core, request(key=k), cache=cache)
        self.assertEqual(len(cache), 2)
        self.assertIsNone(cache.get("a", request(key="a").digest))

    def test_engine_error_becomes_engine_error(self):
        core = StandInCore(fail=StandInCore.Error("the snake collapsed: check the step height"))
        with self.assertRaises(job.EngineError) as ctx:
            job.run_engine(core, request(), cache=None)
        self.assertIn("collapsed", str(ctx.exception))

    def test_auto_smoothness_falls_back_to_the_papers_value_on_an_older_engine(self):
        core = StandInCore(steps=1, supports_auto=False)
        r = request()
        r.kwargs["w_int"] = None
        result = job.run_engine(core, r, cache=None)
        self.assertEqual(core.calls[-1][1]["w_int"], 0.25)
        self.assertTrue(any("0.25" in n for n in result["notes"]))

    def test_estimate_on_an_older_engine_says_what_to_do(self):
        core = StandInCore(steps=1, supports_auto=False)
        r = request()
        r.step_height = None
        with self.assertRaises(job.EngineError) as ctx:
            job.run_engine(core, r, cache=None)
        self.assertIn("Step Height", str(ctx.exception))

    def test_newer_engine_gets_none_through(self):
        core = StandInCore(steps=1)
        r = request()
        r.step_height, r.kwargs["w_int"] = None, None
        job.run_engine(core, r, cache=None)
        self.assertEqual(core.calls[-1], (None, {"w_int": None}))

    def test_cancelled_status_is_a_cancel(self):
        with self.assertRaises(StandInCore.Cancelled):
            job.run_engine(StandInCore(steps=1, status="cancelled"), request(), cache=None)


class Worker(unittest.TestCase):
    def test_runs_in_a_thread_with_progress_snapshots(self):
        core = StandInCore(steps=30)
        j = job.SegmentJob(core, request(), cache=None).start()
        self.assertTrue(j.running)
        self.assertIn(j, job.active_jobs())
        seen = set()
        while not j.done:
            s = j.snapshot()
            seen.add((s.stage, s.points > 0))
            time.sleep(0.005)
        self.assertIn(("coarse", True), seen)
        self.assertIsNone(j.error)
        self.assertFalse(j.cancelled)
        self.assertEqual(j.result["relief_vertices"], [0, 1])
        self.assertNotIn(j, job.active_jobs())
        self.assertGreater(j.snapshot().contour_serial, 0)

    def test_cancel_returns_at_once_and_drops_the_result(self):
        core = StandInCore(steps=1000, step_seconds=0.01)  # ~10 s if not cancelled
        j = job.SegmentJob(core, request(), cache=None).start()
        time.sleep(0.05)
        t = time.perf_counter()
        j.cancel()
        self.assertLess(time.perf_counter() - t, 0.05)  # the main thread never waits for the engine
        self.assertTrue(j.join(2.0))
        self.assertTrue(j.cancelled)
        self.assertIsNone(j.result)

    def test_an_unexpected_exception_ends_the_job_with_an_error(self):
        j = job.SegmentJob(StandInCore(fail=RuntimeError("boom")), request(), cache=None).start()
        self.assertTrue(j.join(2.0))
        self.assertIn("boom", j.error)
        self.assertFalse(j.running)

    def test_cancel_all_stops_every_running_job(self):
        jobs = [job.SegmentJob(StandInCore(steps=1000), request(key=str(i)), cache=None).start() for i in range(2)]
        left = job.cancel_all(wait=2.0)
        self.assertEqual(left, [])
        self.assertTrue(all(j.cancelled for j in jobs))



def _group_work(steps=20, step_seconds=0.01, groups=3, fail=None):
    """A work(mesh, progress) for MeshJob: `groups` reliefs of `steps` progress calls each."""
    def work(mesh, progress):
        if fail:
            raise fail
        for g in range(groups):
            for i in range(steps):
                time.sleep(step_seconds)
                if progress(g, "refine", i, 10 + i, [(g, 0, 0)] * 3) is False:
                    raise StandInCore.Cancelled("cancelled")
        return {"reliefs": list(range(groups)), "mesh": mesh}
    return work


class MeshJobWorker(unittest.TestCase):
    """job.MeshJob: the worker of Detect and Segment Pick Groups (intake and the engine off the main thread)."""

    def buffers(self, z=0.0):
        r = request(z)
        return r.vertices, r.triangles

    def test_runs_the_work_with_the_relief_index_in_the_snapshots(self):
        core = StandInCore()
        j = job.MeshJob(core, *self.buffers(), _group_work(), key=None, cache=None).start()
        self.assertIn(j, job.active_jobs())
        seen = set()
        while not j.done:
            s = j.snapshot()
            seen.add((s.stage, s.index))
            time.sleep(0.005)
        self.assertIsNone(j.error)
        self.assertFalse(j.cancelled)
        self.assertEqual(j.result["reliefs"], [0, 1, 2])
        self.assertTrue({("refine", 0), ("refine", 1), ("refine", 2)} <= seen, seen)
        self.assertEqual(core.meshes_built, 1)
        self.assertNotIn(j, job.active_jobs())
        self.assertEqual(j.digest, job.fingerprint(*self.buffers()))
        self.assertEqual(j.num_vertices, 3)

    def test_the_mesh_comes_from_the_cache_when_it_did_not_change(self):
        core, cache = StandInCore(), job.MeshCache()
        first = job.MeshJob(core, *self.buffers(), _group_work(steps=1), key="Plate", cache=cache).start()
        first.join(5)
        again = job.MeshJob(core, *self.buffers(), _group_work(steps=1), key="Plate", cache=cache).start()
        again.join(5)
        self.assertFalse(first.mesh_cached)
        self.assertTrue(again.mesh_cached)
        self.assertIs(first.result["mesh"], again.result["mesh"])
        moved = job.MeshJob(core, *self.buffers(z=1.0), _group_work(steps=1), key="Plate", cache=cache).start()
        moved.join(5)
        self.assertFalse(moved.mesh_cached)
        self.assertEqual(core.meshes_built, 2)

    def test_cancel_returns_at_once_and_drops_the_result(self):
        j = job.MeshJob(StandInCore(), *self.buffers(), _group_work(steps=1000), cache=None).start()
        time.sleep(0.05)
        t = time.perf_counter()
        j.cancel()
        self.assertLess(time.perf_counter() - t, 0.05)
        self.assertTrue(j.join(2.0))
        self.assertTrue(j.cancelled)
        self.assertIsNone(j.result)
        self.assertIsNone(j.error)

    def test_cancel_during_intake_skips_the_work(self):
        ran = []
        core = StandInCore()
        slow_mesh = core.Mesh

        def slow(vertices, triangles):
            time.sleep(0.2)
            return slow_mesh(vertices, triangles)
        core.Mesh = slow
        j = job.MeshJob(core, *self.buffers(), lambda mesh, progress: ran.append(mesh), cache=None).start()
        time.sleep(0.05)
        self.assertEqual(j.snapshot().stage, "intake")
        j.cancel()
        self.assertTrue(j.join(2.0))
        self.assertTrue(j.cancelled)
        self.assertEqual(ran, [])

    def test_engine_errors_end_the_job_with_their_message(self):
        j = job.MeshJob(StandInCore(), *self.buffers(), _group_work(fail=StandInCore.Error("groups is empty")),
                        cache=None).start()
        self.assertTrue(j.join(2.0))
        self.assertEqual(j.error, "groups is empty")
        j = job.MeshJob(StandInCore(), *self.buffers(), _group_work(fail=KeyError("x")), cache=None).start()
        self.assertTrue(j.join(2.0))
        self.assertIn("KeyError", j.error)

if __name__ == "__main__":
    unittest.main()
