"""relief_snake_batch: runs a manifest of scans through the relief-snake CLI (docs/batch.md).

`relief-snake batch MANIFEST.json --out DIR` hands off to `python3 -m relief_snake_batch`. Each entry
runs as its own `relief-snake segment` or `relief-snake detect` process, so a crash, a hang or bad
input of one entry is recorded in DIR and the run goes on. Locally a pool of `--jobs N` runs the
entries; `--dask local:N` or `--dask tcp://HOST:PORT` runs the same per-entry function on Dask.

Modules: `manifest` (reading and checking the manifest, the command of each entry), `entry_run` (one
entry: the subprocess, its timeout, its record), `records` (what DIR holds, resuming), `executors`
(local pool, Dask), `summary` (the table, summary.json and summary.md), `cli` (the command line).
"""

__version__ = "0.1.0"
