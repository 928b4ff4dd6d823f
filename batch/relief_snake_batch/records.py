"""What DIR holds, and which entries a rerun skips.

    DIR/entries/ID/record.json   one entry's outcome (entry_run.run_entry): status, exit code, signal,
                                 message, start and finish times, seconds, command, fingerprint
    DIR/entries/ID/result.json   the CLI's result document (docs/result-format.md), when it wrote one
    DIR/entries/ID/extract/      segment --extract's files, when the entry asked for them
    DIR/entries/ID/stderr.log    the CLI's stdout and stderr
    DIR/summary.json, summary.md the run's summary (summary.py)

An entry is skipped on a rerun when its record is final (ok, doubtful, failed on its input: exit code
1 or an unreadable picks file, not 2, a command line the CLI refused), its result file is
still there (ok, doubtful), and its fingerprint matches: the settings (the CLI flags, the picks, the
region file's contents) and the mesh's contents (sha256; reused from the record while the file's size
and mtime are unchanged, so an unchanged archive is not read again).
"""
from __future__ import annotations

import json
from pathlib import Path

from .entry_run import FINAL_STATUSES, RECORD_FORMAT, RECORD_NAME, mesh_identity
from .manifest import Entry


def entry_dir(out: Path, entry: Entry) -> Path:
    return out / "entries" / entry.id


def read_record(out: Path, entry: Entry) -> dict | None:
    path = entry_dir(out, entry) / RECORD_NAME
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) and record.get("format") == RECORD_FORMAT else None


def reusable(out: Path, entry: Entry, record: dict | None, settings: str) -> bool:
    """True when the entry's last record still stands for it (see the module's docstring)."""
    if not record or record.get("status") not in FINAL_STATUSES:
        return False
    if record["status"] == "failed" and record.get("exit_code") == 2:
        return False  # the CLI refused the command line itself (an older CLI without detect?): try again
    fingerprint = record.get("fingerprint") or {}
    if fingerprint.get("settings") != settings:
        return False
    if record["status"] in ("ok", "doubtful"):
        if not record.get("result") or not (entry_dir(out, entry) / record["result"]).is_file():
            return False
    recorded_mesh = fingerprint.get("mesh") or {}
    return mesh_identity(entry.mesh, recorded_mesh).get("sha256") == recorded_mesh.get("sha256")
