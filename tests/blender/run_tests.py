"""Runs the add-on test suite inside Blender. One suite, three Blenders:

    blender --background --factory-startup --python-exit-code 1 --python tests/blender/run_tests.py
    .venv-bpy45/bin/python tests/blender/run_tests.py
    .venv-bpy52/bin/python tests/blender/run_tests.py

It enables the add-on from addon/, puts the built native module (build/relief_snake_core*.so,
or $RELIEF_SNAKE_BUILD_DIR) on sys.path, writes two synthetic scans with build/make-scan (a
closed duck relief and an open relief cut by the mesh border) and runs tests/blender/test_*.py.
Exit status is non-zero when anything fails, when a test is skipped, or when bpy, the native
module or make-scan is missing: a suite that did not run is a failure.
"""

import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
BUILD = os.environ.get("RELIEF_SNAKE_BUILD_DIR", os.path.join(ROOT, "build"))
# The module may come from another build of the same sources (bpy 5.2 needs the cp313 one).
MODULE_DIR = os.environ.get("RELIEF_SNAKE_MODULE_DIR", BUILD)


def _exit(code):
    sys.stdout.flush()
    sys.stderr.flush()
    # os._exit: the same behaviour under `blender --python` and the bpy module (no teardown), so
    # Blender's own session directory (bpy.app.tempdir) is removed here.
    try:
        import bpy
        if bpy.app.tempdir and os.path.basename(os.path.normpath(bpy.app.tempdir)).startswith("blender_"):
            shutil.rmtree(bpy.app.tempdir, ignore_errors=True)
    except ImportError:
        pass
    os._exit(code)


def _fail(message):
    print("run_tests: FAILED: %s" % message, file=sys.stderr)
    _exit(1)


def make_scan(out_dir):
    """Writes the test scan and returns (prefix, truth dict)."""
    prefix = os.environ.get("RELIEF_SNAKE_SCAN")
    if not prefix:
        prefix = os.path.join(out_dir, "duck")
        tool = os.path.join(BUILD, "make-scan")
        if not os.path.exists(tool):
            _fail("%s not found: build it first (make build)" % tool)
        cmd = [tool, "--shape", "duck", "--background", "plane", "--triangles",
               os.environ.get("RELIEF_SNAKE_TEST_TRIANGLES", "60000"), "--step", "blended",
               "--seed", "1", "--out", prefix]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(prefix + ".truth.json") as f:
        return prefix, json.load(f)


def make_open_scan(out_dir):
    """The open-contour scan (a relief cut by the mesh's right edge, picks from border to border,
    the relief on their left; the same case as tests/native/test_segment.cpp's open_relief).
    Returns (prefix, truth dict)."""
    prefix = os.path.join(out_dir, "open")
    cmd = [os.path.join(BUILD, "make-scan"), "--shape", "open", "--background", "plane", "--triangles",
           os.environ.get("RELIEF_SNAKE_TEST_TRIANGLES", "60000"), "--step", "blended", "--seed", "1",
           "--out", prefix]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(prefix + ".truth.json") as f:
        return prefix, json.load(f)


def main():
    try:
        import bpy
    except ImportError:
        _fail("bpy is not available: run scripts/install-blender.sh and use Blender or .venv-bpy/bin/python")
    print("run_tests: Blender %s, Python %s" % (bpy.app.version_string, sys.version.split()[0]))

    # The native module, where the add-on's fallback `import relief_snake_core` finds it.
    import sysconfig
    module = os.path.join(MODULE_DIR, "relief_snake_core" + sysconfig.get_config_var("EXT_SUFFIX"))
    if not glob.glob(module):
        _fail("native module %s not found: build it for Python %d.%d (make build, or "
              "scripts/build-wheel.sh --python313)" % (module, *sys.version_info[:2]))
    sys.path.insert(0, MODULE_DIR)
    try:
        import relief_snake_core
    except ImportError as exc:
        _fail("the native module does not import: %s" % exc)
    print("run_tests: engine %s from %s" % (getattr(relief_snake_core, "__version__", "?"),
                                           relief_snake_core.__file__))

    # The add-on, from the source tree, enabled the way Blender enables a legacy add-on.
    import addon_utils
    sys.path.insert(0, os.path.join(ROOT, "addon"))
    mod = addon_utils.enable("relief_snake", default_set=True, handle_error=lambda exc: _fail(
        "enabling the add-on raised %r" % exc))
    if mod is None or not hasattr(bpy.types.Scene, "relief_snake"):
        _fail("the add-on did not register")
    print("run_tests: add-on from %s" % mod.__file__)

    tmp = tempfile.mkdtemp(prefix="relief-snake-blender-")
    prefix, truth = make_scan(tmp)
    open_scan = make_open_scan(tmp)
    sys.path.insert(0, HERE)
    import test_addon
    test_addon.configure(prefix, truth, open_scan=open_scan)

    loader = unittest.TestLoader()
    suite = unittest.TestSuite()
    for name in ("test_pick_order", "test_validation", "test_summary", "test_job", "test_blend_history", "test_placement",
                 "test_region_faces",
                 "test_addon",
                 "test_extraction"):
        suite.addTests(loader.loadTestsFromName(name))
    t0 = time.perf_counter()
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    print("run_tests: %d tests in %.1f s (Blender %s)" % (result.testsRun, time.perf_counter() - t0,
                                                          bpy.app.version_string))
    if result.skipped:
        _fail("%d test(s) skipped; a skipped test counts as a failure" % len(result.skipped))
    if not result.wasSuccessful() or result.testsRun == 0:
        _fail("%d failure(s), %d error(s)" % (len(result.failures), len(result.errors)))
    shutil.rmtree(tmp, ignore_errors=True)  # kept on failure, for the scans it holds
    print("run_tests: OK")
    _exit(0)


if __name__ == "__main__":
    main()
