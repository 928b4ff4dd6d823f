"""The packages made by `make package`: unpack both zips and import the module from them.

Skipped when dist/ (or $RELIEF_SNAKE_DIST) holds no package, i.e. `make package` was not run,
and the Blender installs are skipped when a Blender is missing -- except with
RELIEF_SNAKE_REQUIRE_PACKAGES=1, where each of those is a failure. `make test` (CI) builds the
packages into $(BUILD_DIR)/dist and runs this file that way (the Makefile's test-package).

Each import runs in a subprocess (a second copy of the same extension module cannot be
loaded into this process) and reads /proc/self/maps to prove that libOpenMeshCore comes
from the package, not from the system's libopenmesh. When Blender 3.4 (`blender`) and
bpy 4.2 (.venv-bpy) are present, the zips are also installed and enabled in them.
"""
import base64
import glob
import hashlib
import os
import shutil
import subprocess
import sys
import textwrap
import tomllib
import zipfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DIST = os.environ.get("RELIEF_SNAKE_DIST", os.path.join(ROOT, "dist"))


def _version():
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
        return tomllib.load(f)["project"]["version"]


VERSION = _version()
LEGACY = os.path.join(DIST, "relief_snake-%s-legacy.zip" % VERSION)
EXTENSION = os.path.join(DIST, "relief_snake-%s-linux_x64.zip" % VERSION)

# `make test` sets it: there, a package or Blender that is missing fails instead of skipping.
REQUIRED = os.environ.get("RELIEF_SNAKE_REQUIRE_PACKAGES") == "1"


def need(condition, reason):
    """Skip the test when `condition` is false -- or fail it when packages are required."""
    if not condition:
        if REQUIRED:
            pytest.fail("%s (RELIEF_SNAKE_REQUIRE_PACKAGES=1: nothing may be skipped)" % reason)
        pytest.skip(reason)


@pytest.fixture(scope="module", autouse=True)
def packages_present():  # module scope and autouse: before the zips' fixtures
    need(os.path.exists(LEGACY) or os.path.exists(EXTENSION),
         "no packages in %s: run `make package`" % DIST)

# Imports the module from a folder, uses it, and reports where the module and libOpenMeshCore came from.
IMPORT_CHECK = textwrap.dedent("""
    import sys
    sys.modules["numpy"] = None  # Blender's Python may have no numpy
    sys.path.insert(0, sys.argv[1])
    import array, relief_snake_core as c
    m = c.Mesh(array.array("d", [0, 0, 0, 1, 0, 0, 0, 1, 0]), array.array("i", [0, 1, 2]))
    assert (m.n_vertices, m.n_faces) == (3, 1), m.report
    libs = {line.split()[-1] for line in open("/proc/self/maps") if "libOpenMeshCore" in line}
    print(c.__version__)
    print(c.__file__)
    print(";".join(sorted(libs)))
""")


def import_from(folder):
    out = subprocess.run([sys.executable, "-c", IMPORT_CHECK, folder], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    version, module_file, libs = out.stdout.strip().splitlines()
    return version, module_file, libs.split(";")


def assert_self_contained(folder):
    version, module_file, libs = import_from(folder)
    folder = os.path.realpath(folder)
    assert version == VERSION
    assert os.path.realpath(module_file).startswith(folder + os.sep)
    assert len(libs) == 1 and os.path.realpath(libs[0]).startswith(folder + os.sep), libs


def blender_ext_script():
    found = glob.glob(os.path.join(ROOT, ".venv-bpy", "lib", "python3*", "site-packages", "bpy", "*", "scripts",
                                   "addons_core", "bl_pkg", "cli", "blender_ext.py"))
    return found[0] if found else None


# --- legacy add-on zip (Blender 3.4 .. 4.1: Preferences > Add-ons > Install) ---------------------

@pytest.fixture(scope="module")
def legacy(tmp_path_factory):
    if not os.path.exists(LEGACY):
        pytest.fail("%s is missing while dist/ has packages: rerun `make package`" % LEGACY)
    out = tmp_path_factory.mktemp("legacy")
    with zipfile.ZipFile(LEGACY) as z:
        names = z.namelist()
        z.extractall(out)
    return out, names


def test_legacy_zip_layout(legacy):
    out, names = legacy
    # one top-level folder, the add-on package, with bl_info, the module and its bundled library
    assert {n.split("/")[0] for n in names} == {"relief_snake"}
    assert "relief_snake/__init__.py" in names
    assert any(n.startswith("relief_snake/relief_snake_core.") and n.endswith(".so") for n in names)
    assert "relief_snake/relief_snake_core.libs/libOpenMeshCore.so.9.0" in names
    assert not any("__pycache__" in n or n.endswith(".pyc") for n in names)
    init = (out / "relief_snake" / "__init__.py").read_text()
    assert "bl_info" in init
    # every add-on source file is in the package
    for src in glob.glob(os.path.join(ROOT, "addon", "relief_snake", "*.py")):
        assert "relief_snake/" + os.path.basename(src) in names


def test_legacy_zip_module_imports_with_bundled_openmesh(legacy):
    out, _ = legacy
    assert_self_contained(str(out / "relief_snake"))


def test_legacy_zip_installs_in_blender(tmp_path):
    need(shutil.which("blender") is not None, "Blender 3.4 (blender) not installed")
    script = tmp_path / "install.py"
    script.write_text(textwrap.dedent("""
        import sys, bpy, addon_utils
        bpy.ops.preferences.addon_install(filepath=sys.argv[sys.argv.index("--") + 1])
        addon_utils.enable("relief_snake", default_set=True, handle_error=None)
        from relief_snake import api
        core = api.load_core()
        assert hasattr(bpy.types.Scene, "relief_snake"), "add-on not registered"
        print("CORE", core.__file__)
    """))
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(tmp_path / "scripts"))
    out = subprocess.run(["blender", "--background", "--factory-startup", "--python-exit-code", "1",
                          "--python", str(script), "--", LEGACY], capture_output=True, text=True, env=env,
                         timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    core_lines = [line for line in out.stdout.splitlines() if line.startswith("CORE ")]
    assert core_lines and core_lines[0].split(" ", 1)[1].startswith(str(tmp_path / "scripts" / "addons" / "relief_snake"))


# --- Blender 4.2+ extension zip -------------------------------------------------------------

@pytest.fixture(scope="module")
def extension(tmp_path_factory):
    if not os.path.exists(EXTENSION):
        pytest.fail("%s is missing while dist/ has packages: rerun `make package`" % EXTENSION)
    out = tmp_path_factory.mktemp("extension")
    with zipfile.ZipFile(EXTENSION) as z:
        names = z.namelist()
        z.extractall(out)
    return out, names


def test_extension_manifest(extension):
    out, names = extension
    assert "blender_manifest.toml" in names and "__init__.py" in names
    with open(out / "blender_manifest.toml", "rb") as f:
        manifest = tomllib.load(f)
    assert manifest["schema_version"] == "1.0.0"
    assert manifest["id"] == "relief_snake" and manifest["version"] == VERSION
    assert manifest["name"] == "Relief Snake" and manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert manifest["platforms"] == ["linux-x64"]
    assert manifest["tagline"] and manifest["maintainer"]
    wheels = manifest["wheels"]
    assert wheels == ["./wheels/relief_snake_core-%s-cp311-cp311-linux_x86_64.whl" % VERSION]
    for w in wheels:
        assert w[2:] in names  # the wheel the manifest names is in the zip
    # the extension uses the wheel, never a loose compiled module
    assert not any(n.endswith(".so") for n in names)


def test_extension_wheel_imports_with_bundled_openmesh(extension, tmp_path):
    out, _ = extension
    (wheel,) = glob.glob(str(out / "wheels" / "*.whl"))
    site = tmp_path / "site-packages"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
    assert_self_contained(str(site))


def test_extension_wheel_is_a_consistent_wheel(extension):
    # The wheel is assembled by scripts/build-wheel.sh (--from-build) or scikit-build-core: either
    # way its RECORD must list every file with the right hash and size, and its tag and metadata
    # must be what the manifest and Blender 4.2's Python (CPython 3.11, Linux x86-64) expect.
    out, _ = extension
    (wheel,) = glob.glob(str(out / "wheels" / "*.whl"))
    info = "relief_snake_core-%s.dist-info" % VERSION
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        record = z.read(info + "/RECORD").decode().splitlines()
        entries = {}
        for line in filter(None, record):
            path, digest, size = line.rsplit(",", 2)
            entries[path] = (digest, size)
        assert set(entries) == names, set(entries) ^ names
        for path, (digest, size) in entries.items():
            if path == info + "/RECORD":
                assert (digest, size) == ("", "")
                continue
            data = z.read(path)
            algo, _, want = digest.partition("=")
            assert algo == "sha256" and size == str(len(data)), path
            got = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
            assert got == want, "RECORD hash of %s" % path
        wheel_meta = z.read(info + "/WHEEL").decode()
        metadata = z.read(info + "/METADATA").decode()
    assert "Root-Is-Purelib: false" in wheel_meta
    assert "Tag: cp311-cp311-linux_x86_64" in wheel_meta.splitlines()
    assert "Name: relief_snake_core" in metadata.splitlines()
    assert "Version: %s" % VERSION in metadata.splitlines()
    assert "Requires-Python: >=3.11" in metadata.splitlines()


def test_extension_passes_blenders_validation():
    need(blender_ext_script() is not None, "bpy 4.2 (.venv-bpy) not installed")
    out = subprocess.run([sys.executable, blender_ext_script(), "validate", EXTENSION], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Success" in out.stdout


def test_extension_installs_in_bpy_42(tmp_path):
    need(os.path.exists(os.path.join(ROOT, ".venv-bpy", "bin", "python")), "bpy 4.2 (.venv-bpy) not installed")
    script = tmp_path / "install.py"
    script.write_text(textwrap.dedent("""
        import sys, bpy
        res = bpy.ops.extensions.package_install_files(filepath=sys.argv[1], repo="user_default",
                                                       enable_on_install=True)
        assert res == {"FINISHED"}, res
        from bl_ext.user_default.relief_snake import api
        core = api.load_core()
        assert hasattr(bpy.types.Scene, "relief_snake"), "extension not registered"
        libs = {l.split()[-1] for l in open("/proc/self/maps") if "libOpenMeshCore" in l}
        print("CORE", core.__file__)
        print("LIBS", ";".join(sorted(libs)))
    """))
    # Blender keeps extensions (and their wheels' site-packages) under the user resources folder.
    resources = tmp_path / "resources"
    env = dict(os.environ, HOME=str(tmp_path / "home"), BLENDER_USER_RESOURCES=str(resources))
    out = subprocess.run([os.path.join(ROOT, ".venv-bpy", "bin", "python"), str(script), EXTENSION],
                         capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    lines = dict(line.split(" ", 1) for line in out.stdout.splitlines() if line.startswith(("CORE ", "LIBS ")))
    assert lines["CORE"].startswith(str(resources))
    assert lines["LIBS"] and all(p.startswith(str(resources)) for p in lines["LIBS"].split(";"))
