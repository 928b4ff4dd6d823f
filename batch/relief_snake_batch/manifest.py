"""The batch manifest (docs/batch.md): reading it, checking every key, and each entry's command.

A manifest is a JSON object:

    {"format": "relief-snake-batch/1",            # optional; checked when given
     "description": "...",                        # optional, ignored
     "defaults": {KEY: VALUE, ...},               # optional: applies to every entry
     "entries": [{"mesh": "scans/a.ply", "picks": [1, 2, 3], "h": 1.0}, ...]}

Two kinds of problem are told apart:
* the manifest's structure (not JSON, an unknown key, a value of the wrong type or range, two entries
  with one id): ManifestError, one line naming the entry, and nothing runs (a typo is caught before
  a night's run, not after);
* an entry's input files (a picks file that is missing or unreadable): `Entry.input_error`, recorded as
  that entry's failure while the others run, like a missing or malformed mesh (which the CLI reports).
"""
from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

FORMAT = "relief-snake-batch/1"

TOP_LEVEL_KEYS = ("format", "description", "defaults", "entries")

# Entry ids name the entry's folder in DIR/entries/: letters, digits, '.', '_' and '-'.
ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$")

RELIEF_SIDES = ("left", "right", "auto")
FLATTEN_METHODS = ("auto", "plane", "conformal")


class ManifestError(Exception):
    """A manifest that cannot be run as written; str() is one line that says what to fix."""


@dataclass
class Entry:
    """One scan of the manifest, resolved against the defaults and checked.

    `flags` are the CLI arguments after the mesh path, as run from the entry's own folder
    (DIR/entries/ID/, so the extract folder is the relative `extract`), without `--out`; with the
    mesh's and the region file's contents they make the entry's fingerprint."""
    index: int                       # 1-based place in "entries"
    id: str
    kind: str                        # "segment" or "detect"
    mesh: Path                       # absolute
    flags: list[str] = field(default_factory=list)
    region_vertices: Path | None = None  # detect: absolute; passed as --region-vertices
    timeout: float | None = None     # seconds; None: the run's --timeout
    extract: bool = False
    input_error: str | None = None   # set: the entry is recorded as failed with this message, not run

    @property
    def label(self) -> str:
        return f"entry {self.index} ('{self.id}')"

    def settings_fingerprint(self) -> str:
        """sha256 of what the entry asks for, apart from the mesh's contents (see records.py)."""
        region = file_sha256(self.region_vertices) if self.region_vertices else None
        text = json.dumps({"kind": self.kind, "flags": self.flags, "region_vertices_sha256": region,
                           "input_error": self.input_error}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()


def file_sha256(path: Path) -> str | None:
    """Content hash of a file, or None when it cannot be read (the run reports why)."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


# --- value checks: each takes (value, where) and returns the value to use ---------------------------

def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _number_text(v: float) -> str:
    return str(int(v)) if isinstance(v, int) else repr(float(v))


def _check_bool(v, where):
    if not isinstance(v, bool):
        raise ManifestError(f"{where} must be true or false, got {json.dumps(v)}")
    return v


def _check_mesh(v, where):
    if not isinstance(v, str) or not v.strip():
        raise ManifestError(f"{where} must be a mesh file path (relative to the manifest), got {json.dumps(v)}")
    return v


def _check_id(v, where):
    if not isinstance(v, str) or not ID_PATTERN.match(v):
        raise ManifestError(f"{where} must be a name of letters, digits, '.', '_' or '-' (it names the entry's "
                            f"folder), got {json.dumps(v)}")
    return v


def _check_picks(v, where):
    if isinstance(v, str) and v.strip():
        return v
    if isinstance(v, list) and v and all(isinstance(p, int) and not isinstance(p, bool) and p >= 0 for p in v):
        return v
    raise ManifestError(f"{where} must be a list of 0-based vertex indices or the path of a picks file, "
                        f"got {json.dumps(v)[:80]}")


def _check_h(v, where):
    if v == "auto" or (_is_number(v) and v > 0):
        return v
    raise ManifestError(f"{where} must be a step height > 0 in mesh units or \"auto\", got {json.dumps(v)}")


def _check_w_int(v, where):
    if v == "auto" or (_is_number(v) and 0 < v <= 1):
        return v
    raise ManifestError(f"{where} must be in (0, 1] or \"auto\", got {json.dumps(v)}")


def _check_relief_side(v, where):
    if v not in RELIEF_SIDES:
        raise ManifestError(f"{where} must be \"left\", \"right\" or \"auto\", got {json.dumps(v)}")
    return v


def _check_max_iterations(v, where):
    if isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 100_000_000:
        return v
    raise ManifestError(f"{where} must be a whole number from 1 to 100000000, got {json.dumps(v)}")


def _check_options(v, where):
    if not isinstance(v, dict):
        raise ManifestError(f"{where} must be an object of advanced options (NAME: VALUE; relief-snake --help "
                            f"lists them), got {json.dumps(v)[:80]}")
    for name, value in v.items():
        if not name or "=" in name:
            raise ManifestError(f"{where}: option name {json.dumps(name)} is not a name")
        if not (isinstance(value, (bool, str)) or _is_number(value)):
            raise ManifestError(f"{where}.{name} must be a number, a string or true/false, got {json.dumps(value)}")
    return v


def _check_extract(v, where):
    if isinstance(v, bool):
        return v
    if isinstance(v, dict):
        for key, value in v.items():
            if key == "pixel_size":
                if not (_is_number(value) and value > 0):
                    raise ManifestError(f"{where}.pixel_size must be > 0 (mesh units), got {json.dumps(value)}")
            elif key == "flatten":
                if value not in FLATTEN_METHODS:
                    raise ManifestError(f"{where}.flatten must be one of {', '.join(FLATTEN_METHODS)}, "
                                        f"got {json.dumps(value)}")
            else:
                raise ManifestError(f"{where}: unknown key '{key}'; valid keys: pixel_size, flatten")
        return v
    raise ManifestError(f"{where} must be true, false or an object {{\"pixel_size\": S, \"flatten\": M}}, "
                        f"got {json.dumps(v)[:80]}")


def _check_path(v, where):
    if not isinstance(v, str) or not v.strip():
        raise ManifestError(f"{where} must be a file path (relative to the manifest), got {json.dumps(v)}")
    return v


def _check_degree(v, where):
    if isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 6:
        return v
    raise ManifestError(f"{where} must be a whole number from 0 to 6, got {json.dumps(v)}")


def _check_positive(v, where):
    if _is_number(v) and v > 0:
        return v
    raise ManifestError(f"{where} must be a number > 0, got {json.dumps(v)}")


# key -> (which entries it applies to, check)
KEYS: dict[str, tuple[str, Callable]] = {
    "mesh": ("entry", _check_mesh),
    "id": ("entry", _check_id),
    "detect": ("any", _check_bool),
    "picks": ("segment", _check_picks),
    "h": ("any", _check_h),
    "w_int": ("segment", _check_w_int),
    "closed": ("segment", _check_bool),
    "relief_side": ("segment", _check_relief_side),
    "max_iterations": ("segment", _check_max_iterations),
    "options": ("any", _check_options),
    "extract": ("segment", _check_extract),
    "region_vertices": ("detect", _check_path),
    "min_area": ("detect", _check_positive),
    "background_degree": ("detect", _check_degree),
    "refine": ("detect", _check_bool),
    "allow_partial": ("any", _check_bool),
    "timeout": ("any", _check_positive),
}
DEFAULT_KEYS = [k for k, (scope, _) in KEYS.items() if scope != "entry"]


def _check_keys(obj: dict, allowed: list[str], where: str) -> None:
    for key in obj:
        if key not in allowed:
            raise ManifestError(f"{where}: unknown key '{key}'; valid keys: {', '.join(allowed)}")


def read_picks_file(path: Path) -> list[int]:
    """Picks from a file: a JSON list, a JSON object with "picks" (make-scan's truth file), or
    integers separated by commas or white space. Raises ValueError with a plain message."""
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ValueError(f"picks file {path} not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ValueError(f"picks file {path} cannot be read: {e}") from None
    if path.suffix.lower() == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"picks file {path} is not valid JSON: {e}") from None
        if isinstance(data, dict):
            data = data.get("picks")
        if not (isinstance(data, list) and data and
                all(isinstance(p, int) and not isinstance(p, bool) and p >= 0 for p in data)):
            raise ValueError(f"picks file {path} holds no list of 0-based vertex indices (a list, or \"picks\": [...])")
        return data
    items = [t for t in re.split(r"[,\s]+", text.strip()) if t]
    if not items or not all(t.isdigit() for t in items):
        raise ValueError(f"picks file {path} must hold 0-based vertex indices separated by commas or spaces")
    return [int(t) for t in items]


def _option_flags(e: dict) -> list[str]:
    flags = []
    for name, value in sorted(e.get("options", {}).items()):
        text = ("1" if value else "0") if isinstance(value, bool) else (
            value if isinstance(value, str) else _number_text(value))
        flags += ["--option", f"{name}={text}"]
    return flags


def _detect_flags(e: dict) -> list[str]:
    """CLI flags of a detect entry (relief-snake detect's own; --region-vertices is added at run time)."""
    flags = []
    if "min_area" in e:
        flags += ["--min-area", _number_text(e["min_area"])]
    if isinstance(e.get("h"), (int, float)):  # "auto": detect's default, each candidate's own height
        flags += ["--step-height", _number_text(e["h"])]
    if "background_degree" in e:
        flags += ["--background-degree", str(e["background_degree"])]
    if e.get("refine", True) is False:
        flags.append("--no-refine")
    return flags + _option_flags(e)


def _segment_flags(e: dict, manifest_dir: Path) -> tuple[list[str], str | None]:
    """CLI flags of a segment entry, and an input error (picks file) or None."""
    picks = e.get("picks")
    if picks is None:
        return [], "needs \"picks\" (a list or a picks file) or \"detect\": true"
    if isinstance(picks, str):
        try:
            picks = read_picks_file(manifest_dir / picks)
        except ValueError as err:
            return [], str(err)
    flags = ["--picks", ",".join(str(p) for p in picks)]
    if "h" in e:
        flags += ["--step-height", e["h"] if e["h"] == "auto" else _number_text(e["h"])]
    if "w_int" in e:
        flags += ["--w-int", e["w_int"] if e["w_int"] == "auto" else _number_text(e["w_int"])]
    if e.get("closed", True) is False:
        flags.append("--open")
    if "relief_side" in e:
        flags += ["--relief-side", e["relief_side"]]
    if "max_iterations" in e:
        flags += ["--max-iterations", str(e["max_iterations"])]
    flags += _option_flags(e)
    extract = e.get("extract", False)
    if extract:
        flags += ["--extract", "extract"]
        if isinstance(extract, dict):
            if "pixel_size" in extract:
                flags += ["--pixel-size", _number_text(extract["pixel_size"])]
            if "flatten" in extract:
                flags += ["--flatten", extract["flatten"]]
    return flags, None


def _id_from_mesh(mesh: str, index: int) -> str:
    """An entry's default id: its mesh's file name without the extension, as a folder name."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", Path(mesh).stem).lstrip("._-") or f"entry-{index}"


def parse_manifest(data: Any, manifest_dir: Path) -> list[Entry]:
    """The entries of a parsed manifest (json.load's value), paths resolved against manifest_dir."""
    if not isinstance(data, dict):
        raise ManifestError("the manifest must be a JSON object with \"entries\" (see docs/batch.md)")
    _check_keys(data, list(TOP_LEVEL_KEYS), "the manifest")
    if "format" in data and data["format"] != FORMAT:
        raise ManifestError(f"\"format\" is {json.dumps(data['format'])}; this runner reads \"{FORMAT}\"")
    defaults = data.get("defaults", {})
    if not isinstance(defaults, dict):
        raise ManifestError("\"defaults\" must be an object of entry keys")
    _check_keys(defaults, DEFAULT_KEYS, "\"defaults\"")
    for key, value in defaults.items():
        KEYS[key][1](value, f"defaults.{key}")
    entries = data.get("entries")
    if not isinstance(entries, list) or not entries:
        raise ManifestError("\"entries\" must be a non-empty list of entries ({\"mesh\": ..., \"picks\": ...})")

    result: list[Entry] = []
    seen: dict[str, int] = {}
    for index, raw in enumerate(entries, start=1):
        where = f"entry {index}"
        if not isinstance(raw, dict):
            raise ManifestError(f"{where} must be an object with \"mesh\", got {json.dumps(raw)[:80]}")
        if isinstance(raw.get("id"), str):
            where = f"entry {index} ('{raw['id']}')"
        elif isinstance(raw.get("mesh"), str) and raw["mesh"].strip():
            where = f"entry {index} ('{_id_from_mesh(raw['mesh'], index)}')"
        _check_keys(raw, list(KEYS), where)
        if "mesh" not in raw:
            raise ManifestError(f"{where} has no \"mesh\"")
        for key, value in raw.items():
            KEYS[key][1](value, f"{where}: \"{key}\"")
        if "id" in raw:
            entry_id = raw["id"]
        else:
            entry_id = _id_from_mesh(raw["mesh"], index)
        if entry_id in seen:
            raise ManifestError(f"{where}: entry {seen[entry_id]} has the same id '{entry_id}'"
                                f"{'' if 'id' in raw else ' (from the mesh name)'}; give each entry its own \"id\"")
        seen[entry_id] = index

        merged = {**defaults, **raw}
        if "options" in defaults and "options" in raw:
            merged["options"] = {**defaults["options"], **raw["options"]}
        kind = "detect" if merged.get("detect", False) else "segment"
        # Keys of the other kind: an error when the entry gives them, ignored when they come from the defaults.
        for key in raw:
            scope = KEYS[key][0]
            if scope not in ("any", "entry", kind):
                raise ManifestError(f"{where}: \"{key}\" does not apply to a {kind} entry"
                                    + (" (drop \"detect\": true to segment from picks)" if kind == "detect" else ""))
        merged = {k: v for k, v in merged.items() if KEYS[k][0] in ("any", "entry", kind)}
        if merged.get("closed", True) and "relief_side" in merged:
            raise ManifestError(f"{where}: \"relief_side\" only applies with \"closed\": false")

        entry = Entry(index=index, id=entry_id, kind=kind, mesh=(manifest_dir / merged["mesh"]).resolve(),
                      timeout=merged.get("timeout"))
        if kind == "segment":
            entry.flags, entry.input_error = _segment_flags(merged, manifest_dir)
            entry.extract = bool(merged.get("extract", False))
            if entry.input_error and "picks" not in merged:
                raise ManifestError(f"{where} {entry.input_error}")
        else:
            entry.flags = _detect_flags(merged)
            if "region_vertices" in merged:
                entry.region_vertices = (manifest_dir / merged["region_vertices"]).resolve()
        if merged.get("allow_partial", False):
            entry.flags.append("--allow-partial")
        result.append(entry)
    return result


def load_manifest(path: Path) -> list[Entry]:
    """Reads and checks a manifest file; raises ManifestError (one line) on any problem."""
    try:
        text = Path(path).read_text()
    except FileNotFoundError:
        raise ManifestError("not found; give the path of a manifest JSON file (see docs/batch.md)") from None
    except IsADirectoryError:
        raise ManifestError("is a folder; give the path of a manifest JSON file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ManifestError(f"cannot be read: {e}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise ManifestError(f"is not valid JSON: {e.msg} at line {e.lineno} column {e.colno}") from None
    return parse_manifest(data, Path(path).resolve().parent)
