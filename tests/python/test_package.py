"""The packages made by `make package`: unpack both zips and import the module from them.

Skipped when dist/ (or $RELIEF_SNAKE_DIST) holds no package, i.e. `make package` was not run,
and the Blender installs are skipped when a Blender is missing -- except with
RELIEF_SNAKE_REQUIRE_PACKAGES=1, where each of those is a failure. `make test` (CI) builds the
packages into $(BUILD_DIR)/dist and runs this file that way (the Makefile's test-package).

Each import runs in a subprocess (a second copy of the same extension module cannot be
loaded into this process) and reads /proc/self/maps to prove that libOpenMeshCore comes
from the package, not from the system's libopenmesh. When Blender 3.4 (`blender`), bpy 4.5
(.venv-bpy45) and bpy 5.2 (.venv-bpy52) are present, the zips are also installed and enabled in
them: the legacy zip in 3.4, the cp311 extension in 4.5, the cp313 extension in 5.2.
"""
import base64
import glob
import hashlib
import os
import re
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
# One extension zip per Blender Python: (zip, CPython tag, blender_version_min, max, the bpy venv).
EXTENSIONS = {
    "cp311": (os.path.join(DIST, "relief_snake-%s-blender4.2-5.0-linux_x64.zip" % VERSION), "4.2.0", "5.1.0",
              ".venv-bpy45", (4, 5)),
    "cp313": (os.path.join(DIST, "relief_snake-%s-blender5.1-5.3-linux_x64.zip" % VERSION), "5.1.0", "5.4.0",
              ".venv-bpy52", (5, 2)),
}


def _v(text):
    return tuple(int(x) for x in text.split("."))

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
    need(os.path.exists(LEGACY) or any(os.path.exists(e[0]) for e in EXTENSIONS.values()),
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
    found = glob.glob(os.path.join(ROOT, ".venv-bpy52", "lib", "python3*", "site-packages", "bpy", "*", "scripts",
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


# --- Blender 4.2+ extension zips -----------------------------------------------------------

@pytest.fixture(scope="module", params=sorted(EXTENSIONS))
def extension(request, tmp_path_factory):
    tag = request.param
    path = EXTENSIONS[tag][0]
    if not os.path.exists(path):
        pytest.fail("%s is missing while dist/ has packages: rerun `make package`" % path)
    out = tmp_path_factory.mktemp("extension-" + tag)
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        z.extractall(out)
    return tag, out, names


def test_extension_manifest(extension):
    tag, out, names = extension
    _, lo, hi, _, tested = EXTENSIONS[tag]
    assert "blender_manifest.toml" in names and "__init__.py" in names
    with open(out / "blender_manifest.toml", "rb") as f:
        manifest = tomllib.load(f)
    assert manifest["schema_version"] == "1.0.0"
    assert manifest["id"] == "relief_snake" and manifest["version"] == VERSION
    assert manifest["name"] == "Relief Snake" and manifest["type"] == "add-on"
    assert (manifest["blender_version_min"], manifest["blender_version_max"]) == (lo, hi)
    # the LTS release tested with this zip's Python lies inside its range
    assert _v(manifest["blender_version_min"]) <= tested + (0,) < _v(manifest["blender_version_max"])
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert manifest["platforms"] == ["linux-x64"]
    assert manifest["tagline"] and manifest["maintainer"]
    (wheel,) = manifest["wheels"]
    assert re.fullmatch(r"\./wheels/relief_snake_core-%s-%s-%s-manylinux_2_\d+_x86_64\.whl"
                        % (re.escape(VERSION), tag, tag), wheel), wheel
    assert wheel[2:] in names  # the wheel the manifest names is in the zip
    # the extension uses the wheel, never a loose compiled module
    assert not any(n.endswith(".so") for n in names)


def test_the_two_ranges_do_not_overlap():
    (a_lo, a_hi), (b_lo, b_hi) = [(_v(e[1]), _v(e[2])) for e in (EXTENSIONS["cp311"], EXTENSIONS["cp313"])]
    assert a_hi <= b_lo or b_hi <= a_lo


def test_extension_wheel_imports_with_bundled_openmesh(extension, tmp_path):
    tag, out, _ = extension
    (wheel,) = glob.glob(str(out / "wheels" / "*.whl"))
    site = tmp_path / "site-packages"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
    if tag == "cp%d%d" % sys.version_info[:2]:
        assert_self_contained(str(site))
    else:  # another Python's wheel: at least its module is built for that Python
        assert glob.glob(str(site / ("relief_snake_core.cpython-%s-x86_64-linux-gnu.so" % tag[2:])))


def test_extension_wheel_is_a_consistent_wheel(extension):
    # The wheel is assembled by scripts/build-wheel.sh: its RECORD must list every file with the
    # right hash and size, and its tag and metadata must be what the manifest and Blender's Python
    # expect, with the manylinux policy auditwheel found (not a bare linux_x86_64).
    tag, out, _ = extension
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
    tags = [line for line in wheel_meta.splitlines() if line.startswith("Tag: ")]
    assert len(tags) == 1 and re.fullmatch(r"Tag: %s-%s-manylinux_2_\d+_x86_64" % (tag, tag), tags[0]), tags
    assert os.path.basename(wheel).endswith(tags[0][5:] + ".whl")
    assert "Name: relief_snake_core" in metadata.splitlines()
    assert "Version: %s" % VERSION in metadata.splitlines()
    assert "Requires-Python: >=3.11" in metadata.splitlines()


def test_extension_passes_blenders_validation(extension):
    tag = extension[0]
    need(blender_ext_script() is not None, "bpy 5.2 (.venv-bpy52) not installed")
    out = subprocess.run([sys.executable, blender_ext_script(), "validate", EXTENSIONS[tag][0]], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Success" in out.stdout


@pytest.mark.parametrize("tag", sorted(EXTENSIONS))
def test_extension_installs_in_its_bpy(tag, tmp_path):
    path, _, _, venv, series = EXTENSIONS[tag]
    python = os.path.join(ROOT, venv, "bin", "python")
    need(os.path.exists(python), "bpy %d.%d (%s) not installed" % (series + (venv,)))
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
        print("VERSION", "%d.%d" % bpy.app.version[:2])
        print("CORE", core.__file__)
        print("LIBS", ";".join(sorted(libs)))
    """))
    # Blender keeps extensions (and their wheels' site-packages) under the user resources folder.
    resources = tmp_path / "resources"
    env = dict(os.environ, HOME=str(tmp_path / "home"), BLENDER_USER_RESOURCES=str(resources))
    out = subprocess.run([python, str(script), path], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    lines = dict(line.split(" ", 1) for line in out.stdout.splitlines()
                 if line.startswith(("CORE ", "LIBS ", "VERSION ")))
    assert lines["VERSION"] == "%d.%d" % series
    assert lines["CORE"].startswith(str(resources))
    assert lines["LIBS"] and all(p.startswith(str(resources)) for p in lines["LIBS"].split(";"))
