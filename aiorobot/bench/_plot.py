"""``--plot FILE.png``: the control-period distribution of each executor model.

matplotlib is an optional dependency (``pip install 'aiorobot[plot]'``), imported
only here and only when a plot is asked for.
"""

from __future__ import annotations

from typing import Any

__all__ = ["MATPLOTLIB_MISSING", "matplotlib_available", "write_plot"]

MATPLOTLIB_MISSING = "--plot needs matplotlib, which is not installed: pip install 'aiorobot[plot]' (or matplotlib)"
_COLORS = {"single": "#d62728", "threads": "#ff7f0e", "aiorobot": "#2ca02c"}


def matplotlib_available() -> bool:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def write_plot(doc: dict[str, Any], path: str) -> None:
    """Write the seed experiment's control periods per model and kind to ``path``.

    Top row: each period in order (log scale), one line per model. Bottom row:
    the distribution of periods as an empirical CDF. One column per perception kind.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    seed = doc.get("parts", {}).get("seed")
    if not seed or "models" not in seed:
        raise ValueError("--plot needs the seed part: run without --only, or with --only seed")
    kinds: list[str] = []
    for per_kind in seed["models"].values():
        for kind in per_kind:
            if kind not in kinds:
                kinds.append(kind)
    nominal = 1e3 * seed["config"]["control_period_sec"]
    fig, axes = plt.subplots(2, len(kinds), figsize=(6.5 * len(kinds), 8), squeeze=False)
    for col, kind in enumerate(kinds):
        series_ax, cdf_ax = axes[0][col], axes[1][col]
        for model, per_kind in seed["models"].items():
            res = per_kind.get(kind, {})
            periods = res.get("periods_ms")
            if not periods:
                continue
            stats = res["stats"]
            label = f"{model}: p99 {stats['p99_ms']:.1f}, max {stats['max_ms']:.1f} ms"
            color = _COLORS.get(model)
            series_ax.plot(range(len(periods)), periods, lw=1, color=color, label=label)
            ordered = sorted(periods)
            n = len(ordered)
            cdf_ax.step(ordered, [(i + 1) / n for i in range(n)], where="post", color=color, label=model)
        for ax in (series_ax,):
            ax.axhline(nominal, color="grey", ls="--", lw=0.8)
            ax.set_yscale("log")
            ax.set_xlabel("control period #")
            ax.set_ylabel("period (ms)")
            ax.legend(fontsize=8)
        cdf_ax.axvline(nominal, color="grey", ls="--", lw=0.8)
        cdf_ax.set_xscale("log")
        cdf_ax.set_xlabel("period (ms)")
        cdf_ax.set_ylabel("share of periods <= x")
        cdf_ax.legend(fontsize=8)
        gil = "releases the GIL" if kind == "sleep" else "holds the GIL" if kind == "cpu" else ""
        series_ax.set_title(f"perception work: {kind} ({gil})")
    meta = doc.get("meta", {})
    fig.suptitle(
        f"50 Hz control loop beside 150 ms perception every 100 ms - {meta.get('date_utc', '')}, "
        f"{meta.get('cpus', '?')} CPUs, steal {seed.get('noise', {}).get('steal_pct') or 0:.1f} %"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
