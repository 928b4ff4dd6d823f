"""The benchmark's plots (matplotlib, passed in so a missing matplotlib does not stop the report)."""
from __future__ import annotations

from .cases import PAPER_FIG6, SWEEP_CONFIGS, TARGET_IOU, TARGET_MEAN, TARGET_1M_S, TARGET_290K_S, TARGET_2M_MB
from .report import phase

def plot_sweep(plt, path, rows, xkey, xlabel, title, xmark=None):
    """IoU (left axis) and both mean distances (right axis, log) against x, one line style per
    sweep configuration (solid: the first, usually the engine's defaults)."""
    fig, ax1 = plt.subplots(figsize=(7.5, 5))
    ax2 = ax1.twinx()
    styles = ["-", "--", ":", "-."]
    configs = [c for c, _ in SWEEP_CONFIGS if any(r.get("config") == c for r in rows)]
    tops = [1.0]
    for ci, cname in enumerate(configs):
        mine = sorted((r for r in rows if r.get("config") == cname), key=lambda r: r[xkey])
        ok = [r for r in mine if r.get("ok")]
        bad = [r for r in mine if not r.get("ok")]
        ls = styles[ci % len(styles)]
        xs = [r[xkey] for r in ok]
        ax1.plot(xs, [r["score"]["iou"] for r in ok], "o" + ls, color="tab:blue", label=f"IoU ({cname})")
        ax2.plot(xs, [r["score"]["mean_to_truth"] for r in ok], "s" + ls, color="tab:red",
                 label=f"mean dist contour→truth ({cname})")
        ax2.plot(xs, [r["score"]["mean_from_truth"] for r in ok], "^" + ls, color="tab:orange",
                 label=f"mean dist truth→contour ({cname})")
        if bad:
            ax1.plot([r[xkey] for r in bad], [0.0] * len(bad), "kx" if ci == 0 else "k+", markersize=10,
                     label=f"failed run ({cname})")
        tops += [r["score"]["mean_to_truth"] for r in ok] + [r["score"]["mean_from_truth"] for r in ok]
    ax1.axhline(TARGET_IOU, color="tab:blue", lw=0.8, alpha=0.5)
    ax2.axhline(TARGET_MEAN, color="tab:red", lw=0.8, alpha=0.5)
    if xmark is not None:
        ax1.axvline(xmark, color="gray", lw=0.8, ls="--")
    ax1.set_xlabel(xlabel)
    ax1.set_ylabel("IoU (line: target 0.97)", color="tab:blue")
    ax2.set_ylabel("mean distance, average edges, log (line: target 0.5)", color="tab:red")
    ax1.set_ylim(0, 1.02)
    ax2.set_yscale("log")
    ax2.set_ylim(0.1, max(tops) * 1.5)
    h1, l1 = ax1.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax1.legend(h1 + h2, l1 + l2, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=7)
    ax1.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scaling(plt, path, rows):
    ok = [r for r in rows if r.get("ok") or r.get("engine_seconds") is not None]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    n = [r["triangles"] for r in ok]
    if ok:
        ax1.loglog(n, [r["engine_seconds"] for r in ok], "o-", label="engine total (excl. file reading)")
        ax1.loglog(n, [r["load_seconds"] for r in ok], "s--", label="file reading (load_seconds)")
        # Linear reference through the smallest point.
        ax1.loglog([n[0], n[-1]], [ok[0]["engine_seconds"], ok[0]["engine_seconds"] * n[-1] / n[0]], ":",
                   color="gray", label="linear growth from the first point")
    ax1.plot([290000], [TARGET_290K_S], "r*", markersize=12, label="targets (290k ≤ 1 s, 1M ≤ 3 s)")
    ax1.plot([1000000], [TARGET_1M_S], "r*", markersize=12)
    ax1.set_xlabel("triangles")
    ax1.set_ylabel("seconds")
    ax1.set_title("time vs mesh size (duck, blended step)")
    ax1.legend(fontsize=8)
    ax1.grid(True, which="both", alpha=0.3)
    all_rows = [r for r in rows if r.get("peak_mb")]
    ax2.loglog([r["triangles"] for r in all_rows], [r["peak_mb"] for r in all_rows], "o-",
               label="peak RSS of relief-snake (includes file parsing)")
    ax2.plot([2000000], [TARGET_2M_MB], "r*", markersize=12, label="target: ≤ 1 GB at 2M")
    ax2.set_xlabel("triangles")
    ax2.set_ylabel("MB")
    ax2.set_title("peak memory vs mesh size")
    ax2.legend(fontsize=8)
    ax2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_phases(plt, path, row):
    names = ["preprocess", "coarse", "refine", "stabilise"]
    ours = [(phase(row, n) or {}).get("seconds", 0) for n in names]
    paper = [PAPER_FIG6["phases"][n][2] or 0 for n in names]
    fig, ax = plt.subplots(figsize=(7, 4))
    x = range(len(names))
    ax.bar([i - 0.2 for i in x], paper, 0.4, label=f"paper (2.4 GHz, total {PAPER_FIG6['total_seconds']:.0f} s)")
    ax.bar([i + 0.2 for i in x], ours, 0.4, label=f"ours (total {row.get('engine_seconds', 0):.2f} s)")
    ax.set_yscale("symlog", linthresh=0.1)
    ax.set_xticks(list(x), names)
    ax.set_ylabel("seconds (symlog)")
    ax.set_title(f"Figure 6 analogue ({row.get('triangles', 0):,} triangles): seconds per phase")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


