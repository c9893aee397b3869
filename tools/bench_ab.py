"""A/B the zenoh rows of ``aiorobot bench latency`` between two source trees on one machine.

    git worktree add /tmp/base <rev>
    python tools/bench_ab.py /tmp/base . --runs 3

Runs ``aiorobot.bench._zenoh.run()`` (the full ``--only zenoh`` traffic) with each tree first on
``PYTHONPATH``, alternating A B B A ..., so the machine's load falls on both alike. Each run's
aiorobot figures are divided by bare zenoh-python's of the same run (the bench's own baseline);
the medians over the runs are printed last. On a shared VM compare ratios, not microseconds.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

_CODE = """
import json
from aiorobot.bench import _zenoh
keep, found = {paths!r}, _zenoh.available_paths
if keep:  # the other paths are left out, as if not installed
    _zenoh.available_paths = lambda: {{p: why if p in keep else "left out" for p, why in found().items()}}
print("RESULT " + json.dumps(_zenoh.run(quick={quick})))
"""


def _one(tree: Path, quick: bool, paths: list[str]) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run(
        [sys.executable, "-c", _CODE.format(quick=quick, paths=paths)], env=env, capture_output=True, text=True,
        cwd="/tmp", check=False,
    )
    lines = [line for line in out.stdout.splitlines() if line.startswith("RESULT ")]
    if not lines:
        raise SystemExit(f"the bench failed with {tree} first on PYTHONPATH: {out.stderr.strip()[-400:]}")
    paths = json.loads(lines[0][len("RESULT "):])["paths"]
    a, z = paths["aiorobot"], paths["zenoh"]
    ar, zr = a["burst"]["recv_msgs_per_sec"], z["burst"]["recv_msgs_per_sec"]
    return {
        "small_x": a["small"]["p50_us"] / z["small"]["p50_us"],
        "image_x": a["image"]["p50_us"] / z["image"]["p50_us"],
        "burst_x": statistics.median(ar) / statistics.median(zr) if ar and zr else 0.0,
        "small_p50_us": a["small"]["p50_us"],
        "small_p99_us": a["small"]["p99_us"],
        "image_p50_us": a["image"]["p50_us"],
        "publish_us": a["small"]["send_call"]["p50_us"],
        "publish_image_us": a["image"]["send_call"]["p50_us"],
        "lost": a["small"]["sent"] - a["small"]["n"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a", type=Path, help="a source tree (the folder holding aiorobot/)")
    parser.add_argument("b", type=Path, help="the other source tree")
    parser.add_argument("--runs", type=int, default=3, help="runs of each tree (default 3)")
    parser.add_argument("--quick", action="store_true", help="the bench's quick traffic (noisier)")
    parser.add_argument(
        "--paths", default="", help="only these paths, comma-separated (aiorobot and zenoh always; default: all installed)"
    )
    args = parser.parse_args()
    paths = sorted({"aiorobot", "zenoh", *filter(None, args.paths.split(","))}) if args.paths else []
    from aiorobot.bench._zenoh import available_paths

    unknown = sorted(set(paths) - set(available_paths()))
    if unknown:
        parser.error(f"--paths: expected names among {', '.join(available_paths())}; found {', '.join(unknown)}")
    trees = {"A": args.a.resolve(), "B": args.b.resolve()}
    for name, tree in trees.items():
        if not (tree / "aiorobot" / "__init__.py").is_file():
            parser.error(f"{name}: expected a source tree with aiorobot/__init__.py, found {tree}")
    rows: dict[str, list[dict[str, float]]] = {"A": [], "B": []}
    for i in range(args.runs):
        for name in ("A", "B") if i % 2 == 0 else ("B", "A"):
            row = _one(trees[name], args.quick, paths)
            rows[name].append(row)
            print(name, " ".join(f"{k}={v:.2f}" for k, v in row.items()), flush=True)
    for name, got in rows.items():
        medians = {k: statistics.median(r[k] for r in got) for k in got[0]}
        print(f"median {name} ({trees[name]}):", " ".join(f"{k}={v:.2f}" for k, v in medians.items()))


if __name__ == "__main__":
    main()
