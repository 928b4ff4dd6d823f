"""The run's summary: counts, a table of the entries, DIR/summary.json and DIR/summary.md, the exit code.

Exit code of a run (over every entry of the manifest, skipped ones included, so a rerun that
skips a failure still reports it): 0 every entry ok; 3 none failed but some doubtful; 1 some failed,
crashed or timed out.
"""
from __future__ import annotations

from pathlib import Path

from .entry_run import STATUSES, write_json_atomic

SUMMARY_FORMAT = "relief-snake-batch-summary/1"
# The table printed at the end lists every entry up to this many, else the ones that are not ok.
PRINT_ALL_UP_TO = 200


def exit_code(counts: dict[str, int]) -> int:
    if counts.get("failed", 0) or counts.get("crashed", 0) or counts.get("timeout", 0):
        return 1
    return 3 if counts.get("doubtful", 0) else 0


def make_summary(rows: list[dict], meta: dict) -> dict:
    """rows: one per manifest entry, in manifest order: the record plus "skipped" (bool)."""
    counts = {s: 0 for s in STATUSES}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    entries = [{"id": r["id"], "index": r["index"], "kind": r.get("kind"), "status": r["status"],
                "skipped": r["skipped"], "exit_code": r.get("exit_code"), "signal": r.get("signal"),
                "result_status": r.get("result_status"), "seconds": r.get("seconds", 0.0),
                "started": r.get("started"), "finished": r.get("finished"), "message": r.get("message", ""),
                "result": f"entries/{r['id']}/{r['result']}" if r.get("result") else None,
                "extract": f"entries/{r['id']}/{r['extract']}" if r.get("extract") else None}
               for r in rows]
    ran = [r for r in rows if not r["skipped"]]
    return {"format": SUMMARY_FORMAT, **meta, "entries_total": len(rows), "ran": len(ran),
            "skipped": len(rows) - len(ran), "counts": counts,
            "entry_seconds_ran": round(sum(r.get("seconds", 0.0) for r in ran), 3),
            "exit_code": exit_code(counts), "entries": entries}


def counts_line(summary: dict) -> str:
    c = summary["counts"]
    return (", ".join(f"{c[s]} {s}" for s in STATUSES) +
            f"; {summary['ran']} ran, {summary['skipped']} skipped (finished before); "
            f"{summary['wall_seconds']:.1f} s wall, {summary['entry_seconds_ran']:.1f} s in the entries run "
            f"({summary['executor']})")


def _cell(text: str, width: int) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= width else text[: width - 1] + "…"


def table(entries: list[dict], markdown: bool) -> str:
    header = ["entry", "status", "exit", "seconds", "skipped", "message"]
    rows = []
    for e in entries:
        exit_text = e["signal"] if e.get("signal") else ("" if e["exit_code"] is None else str(e["exit_code"]))
        rows.append([e["id"], e["status"], exit_text, f"{e['seconds']:.2f}", "yes" if e["skipped"] else "",
                     e["message"] if markdown else _cell(e["message"], 70)])
    if markdown:
        def md(cells):
            return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"
        return "\n".join([md(header), md(["---"] * len(header))] + [md(r) for r in rows])
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    aligned = ["<", "<", ">", ">", "<", "<"]
    return "\n".join("  ".join(f"{str(c):{a}{w}}" for c, a, w in zip(r, aligned, widths)).rstrip()
                     for r in [header] + rows)


def printed_table(summary: dict) -> str:
    entries = summary["entries"]
    if len(entries) <= PRINT_ALL_UP_TO:
        return table(entries, markdown=False)
    others = [e for e in entries if e["status"] != "ok"]
    note = f"({len(entries) - len(others)} ok entries not listed: see summary.md)"
    return (table(others, markdown=False) + "\n" + note) if others else note


def write_summary(out: Path, summary: dict) -> None:
    write_json_atomic(out / "summary.json", summary)
    text = (f"# Batch summary\n\nManifest `{summary['manifest']}`, {summary['started']} to {summary['finished']}.\n\n"
            f"{counts_line(summary)}; exit code {summary['exit_code']}.\n\n{table(summary['entries'], markdown=True)}\n")
    tmp = out / ".summary.md.partial"
    tmp.write_text(text)
    tmp.replace(out / "summary.md")
