"""Issue 14's contract on a fixed sample of the randomized suite (bench/random_suite.py).

Twenty scans drawn by `make-scan --random SEED` for seeds 1000..1019, a held-out sample (the benchmark
measures seeds 0..199), segmented with the engine's defaults through the CLI, as a user would run
it with an h typed anywhere from x0.5 to x2.0 of the true step. The contract:

* every wrong result is flagged: no result that misses the truth (mean distance over one average edge
  either way, or area-weighted IoU under the one-edge floor) comes back as exit code 0 and status
  `converged`;
* at least MIN_ACCURATE of the scans are accurate.

The benchmark's target is 97% accurate on the 200-scan suite; on 20 scans one failure already costs
5%, so this sample asks for 18 of 20.

The same twenty scans are also segmented with `--step-height auto` (h estimated, the engine's default
mode), held to what was measured there (test_auto_h_no_worse_than_measured), and with the side of the
open ones left to the engine too (variant auto-side, the CLI's own defaults).
"""
import json
import sys
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]

SEEDS = "1000:1020"
MIN_ACCURATE = 0.9


def run_sample(build_dir, out, variant):
    sys.path.insert(0, str(REPO_ROOT))
    from bench import random_suite

    for exe in ("relief-snake", "make-scan"):
        if not (build_dir / exe).is_file():
            pytest.fail(f"{build_dir / exe} not found: build the relief-snake and make-scan targets")
    code = random_suite.main(["--cli", str(build_dir / "relief-snake"), "--make-scan", str(build_dir / "make-scan"),
                              "--seeds", SEEDS, "--jobs", "2", "--variant", variant, "--real-scan", "",
                              "--timeout", "60", "--out", str(out)])
    assert code == 0
    data = json.loads((out / "results.json").read_text())
    rows = data["rows"][variant]
    assert len(rows) == 20
    return rows


@pytest.fixture(scope="module")
def sample(build_dir, tmp_path_factory):
    return run_sample(build_dir, tmp_path_factory.mktemp("random-suite"), "defaults")


@pytest.fixture(scope="module")
def auto_h_sample(build_dir, tmp_path_factory):
    """The same scans with h left to the engine (`--step-height auto`, the default mode)."""
    return run_sample(build_dir, tmp_path_factory.mktemp("random-suite-auto-h"), "auto-h")


def describe(row):
    a, s = row["axes"], row.get("score") or {}
    return (f"{row['case']} ({a.get('shape')}, {a.get('background')}, texture {a.get('texture')}, {a.get('step')}, "
            f"detail {a.get('detail')}, start {a.get('start')}, h/edge {a.get('h_edges', 0):.1f}, typed x"
            f"{a.get('typed_factor', 0):.2f}): IoU {s.get('iou_area', float('nan')):.3f} (floor "
            f"{s.get('iou_floor_area', float('nan')):.3f}), mean {s.get('mean_to_truth', float('nan')):.2f} / "
            f"{s.get('mean_from_truth', float('nan')):.2f} edges")


def test_every_wrong_result_is_flagged(sample):
    silent = [r for r in sample if not r["accurate"] and not r["flagged"]]
    assert not silent, "wrong results reported as converged:\n" + "\n".join(describe(r) for r in silent)


# 18 of 20 since the coarse-overlap check asks whether refinement lost relief or only background
# (3 December 2026): seed 1010, a C, now keeps the attempt that let go of its bridged gap. Before,
# 17 of 20, and this test was marked as the known failure.
def test_most_results_are_accurate(sample):
    accurate = sum(r["accurate"] for r in sample)
    wrong = [r for r in sample if not r["accurate"]]
    assert accurate >= MIN_ACCURATE * len(sample), (
        f"{accurate} of {len(sample)} accurate (wanted >= {MIN_ACCURATE:.0%}); wrong:\n"
        + "\n".join(describe(r) + f" [{r['outcome']}]" for r in wrong))


# What the engine achieved on this sample when the marks above were set; any regression fails.
MEASURED_ACCURATE = 18
MEASURED_SILENT = 0


def assert_no_worse(rows, measured_accurate, measured_silent):
    accurate = sum(r["accurate"] for r in rows)
    silent = [r for r in rows if not r["accurate"] and not r["flagged"]]
    assert accurate >= measured_accurate and len(silent) <= measured_silent, (
        f"{accurate} of {len(rows)} accurate (measured {measured_accurate}), {len(silent)} silent "
        f"(measured {measured_silent}):\n" + "\n".join(describe(r) for r in silent))


def test_no_worse_than_measured(sample):
    assert_no_worse(sample, MEASURED_ACCURATE, MEASURED_SILENT)


# With h estimated the sample is not yet free of silent failures: seeds 1003 and 1014 come back wrong
# and `converged` (3 December 2026, as before the estimate's further guesses). This guards against
# regressions until the contract above holds for it too.
MEASURED_AUTO_H_ACCURATE = 17
MEASURED_AUTO_H_SILENT = 2


def test_auto_h_no_worse_than_measured(auto_h_sample):
    assert_no_worse(auto_h_sample, MEASURED_AUTO_H_ACCURATE, MEASURED_AUTO_H_SILENT)


@pytest.fixture(scope="module")
def auto_side_sample(build_dir, tmp_path_factory):
    """The same scans with the CLI's own defaults: h and an open contour's relief side left to the engine."""
    return run_sample(build_dir, tmp_path_factory.mktemp("random-suite-auto-side"), "auto-side")


# Measured on 4 December 2026 (engine of 482455e): 17 accurate, seeds 1003 and 1014 silent as with the
# side given; before open contours' sides were tried both ways, 16 (seed 1005's decided side was wrong).
MEASURED_AUTO_SIDE_ACCURATE = 17
MEASURED_AUTO_SIDE_SILENT = 2


def test_auto_side_no_worse_than_measured(auto_side_sample):
    assert_no_worse(auto_side_sample, MEASURED_AUTO_SIDE_ACCURATE, MEASURED_AUTO_SIDE_SILENT)


def test_the_step_is_also_scored_against_the_rim(auto_h_sample):
    """Each run's measured step is scored against h and against the rim the relief's edge reaches
    (make-scan's edge_step_height), which is never above h: the rim's ratio is never the smaller."""
    measured = [r for r in auto_h_sample if r.get("h_measured_ratio")]
    assert measured, "no run measured a step"
    for r in measured:
        assert "h_measured_rim_ratio" in r, r["case"]
        assert r["h_measured_rim_ratio"] >= r["h_measured_ratio"] * (1 - 1e-12), r["case"]


def test_seeds_take_ranges_and_single_seeds_in_one_list():
    sys.path.insert(0, str(REPO_ROOT))
    from bench.random_suite import parse_seeds

    assert parse_seeds("0:3,10:12,7") == [0, 1, 2, 10, 11, 7]
    assert parse_seeds("1000:1020") == list(range(1000, 1020))
    for bad in ("a:b", "1:x", ","):
        with pytest.raises(SystemExit, match="--seeds"):
            parse_seeds(bad)
