"""The engine side of a segmentation, without bpy: the request, the engine call with its
mesh cache, and the worker thread the interactive operator polls.

    request = Request(vertices, triangles, picks, step_height, kwargs)   # filled by api.prepare
    result = run_engine(core, request)                                     # blocking
    job = SegmentJob(core, request); job.start(); job.poll(); job.cancel() # worker thread
    job = MeshJob(core, vertices, triangles, lambda mesh, progress: mesh.detect(progress=progress))

Nothing here touches Blender data, so the worker thread may run it and plain Python can
test it (tests/blender/test_job.py). Blender data is read before (api.prepare) and written
after (api.apply_result), on the main thread.
"""

import hashlib
import threading
import time

__all__ = ["EngineError", "Request", "fingerprint", "MeshCache", "MESH_CACHE", "run_engine",
           "SegmentJob", "MeshJob", "active_jobs", "cancel_all"]


class EngineError(RuntimeError):
    """Any failure worth a one-line user report (bad input, engine error, missing module)."""


def fingerprint(vertices, triangles):
    """A digest of the mesh data the engine sees: vertex positions (flat 3*#V floats) and
    triangles (flat 3*#T ints), both buffers (array.array, memoryview, bytes). Equal digests
    mean the engine would build the same mesh, so its cached Mesh (intake and planarity) can be
    reused, and a digest that changed during a run means the user edited the mesh meanwhile."""
    h = hashlib.blake2b(digest_size=16)
    for buf in (vertices, triangles):
        view = memoryview(buf)
        h.update(b"%d:%s;" % (view.nbytes, view.format.encode()))
        h.update(view.cast("B"))
    return h.hexdigest()


class Request:
    """What the engine needs for one segmentation, read from Blender on the main thread.

    vertices: flat 3*#V float32 buffer (object space); triangles: flat 3*#T int32 buffer;
    picks: list of vertex indices in order; step_height: h > 0, or None to let the engine
    estimate it; kwargs: the engine's keyword arguments (w_int, open_contour, relief_side,
    max_iterations, advanced options); key: what identifies the mesh in the cache (the object's
    name); digest: fingerprint(vertices, triangles), computed on first use; read_seconds: time
    spent reading Blender data.
    """

    def __init__(self, vertices, triangles, picks, step_height, kwargs, key=None, read_seconds=0.0):
        self.vertices, self.triangles = vertices, triangles
        self.picks = [int(p) for p in picks]
        self.step_height = step_height
        self.kwargs = dict(kwargs)
        self.key = key
        self._digest = None
        self.read_seconds = read_seconds
        self.num_vertices = len(vertices) // 3

    @property
    def digest(self):
        """fingerprint(vertices, triangles), computed on first use: by run_engine, so in an
        interactive run the worker thread hashes the buffers, not Blender's main thread."""
        if self._digest is None:
            self._digest = fingerprint(self.vertices, self.triangles)
        return self._digest


class MeshCache:
    """The engine's Mesh objects (relief_snake_core.Mesh: the validated mesh plus its Segmenter,
    which keeps the planarity between segmentations) for the last few meshes, by key and digest.
    A second Segment on the same, unchanged scan skips mesh intake and, with the same h, the
    planarity. Any change to the positions or the triangles changes the digest and rebuilds."""

    def __init__(self, size=2):
        self.size = size
        self._entries = []  # [(key, digest, mesh)], most recent last
        self._lock = threading.Lock()

    def get(self, key, digest):
        with self._lock:
            for i, (k, d, mesh) in enumerate(self._entries):
                if k == key and d == digest:
                    self._entries.append(self._entries.pop(i))
                    return mesh
        return None

    def put(self, key, digest, mesh):
        with self._lock:
            self._entries = [e for e in self._entries if e[0] != key]
            self._entries.append((key, digest, mesh))
            del self._entries[:-self.size]

    def clear(self):
        with self._lock:
            self._entries = []

    def __len__(self):
        return len(self._entries)


MESH_CACHE = MeshCache()

# Engine features that this add-on uses when the built module has them (issue 14's contract):
# w_int=None ("engine chooses the smoothness") and step_height=None ("estimate h"). Detected
# once per module by trying: pybind11 refuses None for a float argument with a TypeError
# before any work is done.
_UNSUPPORTED = "incompatible function arguments"


def _call(segment, request, progress, notes):
    kwargs = dict(request.kwargs)
    try:
        return segment(request.picks, request.step_height, progress=progress, **kwargs)
    except TypeError as exc:
        if _UNSUPPORTED not in str(exc):
            raise EngineError(str(exc)) from None  # e.g. an unknown advanced option
        if request.step_height is None:
            raise EngineError("This build of the engine cannot estimate the step height yet: type the "
                              "Step Height or use Measure") from None
        if kwargs.get("w_int") is None:
            kwargs["w_int"] = 0.25
            notes.append("this build of the engine does not choose the smoothness itself yet; used 0.25 "
                         "(the paper's value)")
            try:
                return segment(request.picks, request.step_height, progress=progress, **kwargs)
            except TypeError as again:  # e.g. an unknown advanced option
                raise EngineError(str(again)) from None
        raise EngineError(str(exc)) from None


def run_engine(core, request, progress=None, cache=MESH_CACHE, on_stage=None):
    """Segment `request` with relief_snake_core `core`; no bpy access, so it may run in a worker.

    Reuses the cached engine Mesh for (request.key, request.digest) when there is one. Returns the
    engine's result dict plus "timing" {"read", "intake", "engine", "write"} seconds and
    "mesh_cached" (bool). Raises EngineError with the engine's message, or core.Cancelled when
    `progress` returned False. on_stage(name) is told "intake" and "segment" as they start.
    """
    t0 = time.perf_counter()
    notes = []
    mesh = cache.get(request.key, request.digest) if cache is not None and request.key else None
    cached = mesh is not None
    try:
        if mesh is None:
            if on_stage:
                on_stage("intake")
            mesh = core.Mesh(request.vertices, request.triangles)
            if cache is not None and request.key:
                cache.put(request.key, request.digest, mesh)
        t1 = time.perf_counter()
        if on_stage:
            on_stage("segment")
        result = _call(mesh.segment, request, progress, notes)
    except core.Error as exc:
        raise EngineError(str(exc)) from None
    t2 = time.perf_counter()
    result = dict(result)
    if result.get("status") == "cancelled":
        raise core.Cancelled("segmentation cancelled")
    result["notes"] = list(result.get("notes", [])) + notes
    result["mesh_cached"] = cached
    # The engine's own timing (load_seconds, segment_seconds) plus the add-on's side of it.
    result["timing"] = dict(result.get("timing") or {}, read=request.read_seconds, intake=t1 - t0,
                            engine=t2 - t0, write=0.0)
    return result


class Snapshot:
    """The latest progress, copied for the main thread: stage ("intake", "segment" or the
    engine's phase name), iteration, points (snaxels), contour (list of (x, y, z) or None),
    contour_serial (counts contour updates, so the viewport rebuilds its batch only on change),
    seconds since start, and index (the relief a MeshJob is on: the group, or the candidate)."""

    __slots__ = ("stage", "iteration", "points", "contour", "contour_serial", "seconds", "index")

    def __init__(self, stage="waiting", iteration=0, points=0, contour=None, contour_serial=0, seconds=0.0,
                 index=0):
        self.stage, self.iteration, self.points = stage, iteration, points
        self.contour, self.contour_serial, self.seconds = contour, contour_serial, seconds
        self.index = index


_ACTIVE = set()
_ACTIVE_LOCK = threading.Lock()


def active_jobs():
    """Jobs whose worker is still running (including abandoned ones that are winding down)."""
    with _ACTIVE_LOCK:
        return [j for j in _ACTIVE if j.running]


def cancel_all(wait=0.0):
    """Ask every running job to stop (add-on unregister, file load); wait up to `wait` seconds in total."""
    jobs = active_jobs()
    for j in jobs:
        j.cancel()
    deadline = time.perf_counter() + wait
    for j in jobs:
        j.join(max(0.0, deadline - time.perf_counter()))
    return [j for j in jobs if j.running]


class _WorkerJob:
    """One engine call in a worker thread. The main thread polls snapshot() and done, and reads
    result / error / cancelled once done. cancel() only sets a flag and returns at once: the
    engine stops at its next progress call; a job cancelled while in mesh intake finishes intake
    first (intake has no progress callback) and its result is then discarded. Subclasses give
    _run() (the work, in the worker)."""

    def __init__(self, core, cache=MESH_CACHE):
        self.core, self.cache = core, cache
        self.result = None
        self.error = None
        self.cancelled = False
        self._cancel = threading.Event()
        self._done = threading.Event()
        self._lock = threading.Lock()
        self._snap = Snapshot()
        self._t0 = None
        self._thread = None

    # -- worker side -----------------------------------------------------------------------
    def _stage(self, name):
        with self._lock:
            self._snap.stage = name

    def _progress(self, phase, iteration, snaxels, contour, index=None):
        with self._lock:
            s = self._snap
            s.stage, s.iteration, s.points = phase, iteration, snaxels
            if index is not None:
                s.index = index
            if contour is not None:  # the engine sends it at most every 0.1 s
                s.contour = contour
                s.contour_serial += 1
        return not self._cancel.is_set()

    def _run(self):
        raise NotImplementedError

    def _work(self):
        try:
            self.result = self._run()
        except self.core.Cancelled:
            self.cancelled = True
        except EngineError as exc:
            self.error = str(exc)
        except self.core.Error as exc:
            self.error = str(exc)
        except Exception as exc:  # keep the UI alive: report it instead of a silent thread death
            self.error = "Relief Snake failed: %s: %s" % (type(exc).__name__, exc)
        finally:
            if self._cancel.is_set():
                self.cancelled, self.result = True, None
            self._done.set()
            with _ACTIVE_LOCK:
                _ACTIVE.discard(self)

    # -- main-thread side ------------------------------------------------------------------
    def start(self):
        self._t0 = time.perf_counter()
        self._thread = threading.Thread(target=self._work, name="relief-snake", daemon=True)
        with _ACTIVE_LOCK:
            _ACTIVE.add(self)
        self._thread.start()
        return self

    def cancel(self):
        self._cancel.set()

    @property
    def cancel_requested(self):
        return self._cancel.is_set()

    @property
    def done(self):
        return self._done.is_set()

    @property
    def running(self):
        return self._thread is not None and not self._done.is_set()

    def join(self, timeout=None):
        return self._done.wait(timeout)

    def snapshot(self):
        with self._lock:
            s = self._snap
            return Snapshot(s.stage, s.iteration, s.points, s.contour, s.contour_serial,
                            time.perf_counter() - (self._t0 or time.perf_counter()), s.index)


class SegmentJob(_WorkerJob):
    """One segmentation (run_engine on a Request) in a worker thread."""

    def __init__(self, core, request, cache=MESH_CACHE):
        super().__init__(core, cache)
        self.request = request

    def _run(self):
        return run_engine(self.core, self.request, self._progress, self.cache, self._stage)


class MeshJob(_WorkerJob):
    """Several reliefs in one engine call in a worker thread: the engine Mesh of (vertices,
    triangles) is taken from the cache or built there (intake off the main thread too), then
    work(mesh, progress) runs, e.g. lambda mesh, progress: mesh.detect(progress=progress).
    progress(index, phase, iteration, snaxels, contour) is the engine's group progress; the
    snapshot's index is the relief being segmented. digest: fingerprint(vertices, triangles),
    to check before writing that the mesh did not change meanwhile."""

    def __init__(self, core, vertices, triangles, work, key=None, cache=MESH_CACHE):
        super().__init__(core, cache)
        self.vertices, self.triangles, self.work, self.key = vertices, triangles, work, key
        self._digest = None
        self.num_vertices = len(vertices) // 3
        self.mesh_cached = False

    @property
    def digest(self):
        """fingerprint(vertices, triangles), computed on first use (in the worker, by _run)."""
        if self._digest is None:
            self._digest = fingerprint(self.vertices, self.triangles)
        return self._digest

    def _group_progress(self, index, phase, iteration, snaxels, contour):
        return self._progress(phase, iteration, snaxels, contour, index)

    def _run(self):
        cache = self.cache if self.key else None
        digest = self.digest  # hashed here, off the main thread; mesh_changed() compares it once done
        mesh = cache.get(self.key, digest) if cache is not None else None
        self.mesh_cached = mesh is not None
        if mesh is None:
            self._stage("intake")
            mesh = self.core.Mesh(self.vertices, self.triangles)
            if cache is not None:
                cache.put(self.key, digest, mesh)
        if self._cancel.is_set():
            raise self.core.Cancelled("cancelled during mesh intake")
        self._stage("segment")
        return self.work(mesh, self._group_progress)
