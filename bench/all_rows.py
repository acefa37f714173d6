"""Run every issue-18 bench that writes JSON records, merge their rows, and draw them against their goals.

Run: python bench/all_rows.py [--quick] [--only NAME,...] [--out bench/results/latest.json]
     [--plot docs/perf-rows.png] [--from FILE]

Each bench in ``BENCHES`` that exists and offers ``--json`` is run in turn (with ``--quick`` when asked
and it offers it) and writes a list of records ``{row, value, anchor, ratio, unit, goal, met}``. The
rows are merged into one JSON file (with the machine, its load average before each bench, and how long
each bench took), printed as a Markdown table, and drawn: one bar per row, how far it is from its goal
(1.0 is the goal; right of it is better), green where met. ``--from FILE`` redraws a merged file
without running anything. Needs matplotlib (the ``eval`` extra) for the plot.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import re
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BENCHES = (
    "store_limits.py",
    "startup_and_scale.py",
    "rosbridge*.py",
    "match_scale.py",
    "sim_rtf.py",
    "cold_match.py",
)
"""The issue-18 benches, in the order they run (a glob may name several)."""
_GOAL = re.compile(r"^\s*(>=|<=)\s*([0-9.]+)\s*(x?)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="pass --quick to the benches that offer it")
    parser.add_argument("--only", help="comma-separated bench file names to run (default: all found)")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "latest.json", help="merged JSON file")
    parser.add_argument("--plot", type=Path, default=ROOT / "docs" / "perf-rows.png", help="the plot (PNG)")
    parser.add_argument("--from", dest="source", type=Path, help="redraw this merged file; run nothing")
    args = parser.parse_args()
    if args.source is not None:
        merged = json.loads(args.source.read_text(encoding="utf-8"))
    else:
        merged = run_all(args.quick, args.only.split(",") if args.only else None)
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(merged, indent=2) + "\n", encoding="utf-8")
        print(f"\nwritten to {args.out}")
    print()
    print(markdown(merged["rows"]))
    draw(merged, args.plot)
    print(f"\nplot: {args.plot}")


def found_benches(only: list[str] | None) -> list[Path]:
    paths = [path for pattern in BENCHES for path in sorted(HERE.glob(pattern))]
    unique = list(dict.fromkeys(paths))
    return [path for path in unique if only is None or path.name in only]


def run_all(quick: bool, only: list[str] | None) -> dict[str, Any]:
    machine = f"{platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}"
    print(f"machine: {machine}")
    merged: dict[str, Any] = {
        "machine": machine,
        "when": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "quick": quick,
        "benches": {},
        "rows": [],
    }
    for path in found_benches(only):
        usage = subprocess.run([sys.executable, str(path), "--help"], capture_output=True, text=True, cwd=ROOT)
        if "--json" not in usage.stdout:
            merged["benches"][path.name] = {"status": "skipped: no --json"}
            print(f"== {path.name}: skipped (no --json)")
            continue
        with tempfile.TemporaryDirectory() as folder:
            target = Path(folder) / "rows.json"
            argv = [sys.executable, str(path), "--json", str(target)]
            if quick and "--quick" in usage.stdout:
                argv.append("--quick")
            load = os.getloadavg()[0]
            print(f"== {path.name} (load average {load:.2f}): {' '.join(argv[1:])}", flush=True)
            start = time.perf_counter()
            done = subprocess.run(argv, cwd=ROOT, check=False)
            seconds = time.perf_counter() - start
            status = "ok" if done.returncode == 0 and target.exists() else f"failed (exit {done.returncode})"
            merged["benches"][path.name] = {"status": status, "seconds": round(seconds, 1), "load_average": load}
            if status != "ok":
                continue
            records = json.loads(target.read_text(encoding="utf-8"))
        for record in records:
            merged["rows"].append({"bench": path.name, **record})
    return merged


def attainment(record: dict[str, Any]) -> float | None:
    """How far a row is from its goal, 1.0 being the goal and more being better; None for a goal that
    is not a bound (``composes``) or a row without the figure its goal is about."""
    match = _GOAL.match(str(record.get("goal", "")))
    if match is None:
        return None
    sign, limit, relative = match.group(1), float(match.group(2)), match.group(3) == "x"
    measure = record.get("ratio") if relative else record.get("value")
    if measure is None or limit <= 0 or measure <= 0:
        return None
    return measure / limit if sign == ">=" else limit / measure


def markdown(rows: list[dict[str, Any]]) -> str:
    lines = ["| bench | row | cbrs | anchor | ratio | unit | goal | met |", "|---|---|---|---|---|---|---|---|"]
    for record in rows:
        lines.append(
            f"| {record['bench']} | {record['row']} | {_number(record.get('value'))} | "
            f"{_number(record.get('anchor'))} | {_number(record.get('ratio'), 'x')} | {record.get('unit', '')} | "
            f"{record.get('goal', '')} | {'yes' if record.get('met') else '**no**'} |"
        )
    return "\n".join(lines)


def _number(value: Any, suffix: str = "") -> str:
    if value is None:
        return ""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return str(value)
    if abs(value) >= 1000:
        return f"{value:,.0f}{suffix}"
    return f"{value:.3g}{suffix}"


def draw(merged: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [(record, attainment(record)) for record in merged["rows"]]
    shown = [(record, value) for record, value in rows if value is not None]
    labels = [textwrap.shorten(f"{record['row']} ({record['goal']})", 64, placeholder="...") for record, _ in shown]
    values = [value for _, value in shown]
    colours = ["#2e7d32" if record.get("met") else "#c62828" for record, _ in shown]
    height = max(2.5, 0.32 * len(shown) + 1.2)
    figure, axes = plt.subplots(figsize=(11, height))
    positions = list(range(len(shown)))[::-1]
    axes.hlines(positions, 1.0, values, colors=colours, linewidth=4)  # from the goal to the figure
    axes.scatter(values, positions, color=colours, zorder=3)
    axes.axvline(1.0, color="black", linewidth=1)
    axes.set_yticks(positions, labels, fontsize=8)
    axes.set_xscale("log")
    low = min([*values, 0.5])
    high = max([*values, 2.0])
    axes.set_xlim(10 ** math.floor(math.log10(low)), 10 ** math.ceil(math.log10(high)))
    axes.set_xlabel("figure relative to its goal (1 = goal; right of the line is better; log scale)")
    when = merged.get("when", "")
    loads = [bench["load_average"] for bench in merged.get("benches", {}).values() if "load_average" in bench]
    if loads:
        when += f", load average {min(loads):.1f}-{max(loads):.1f} before the benches"
    title = f"Issue 18 rows, {'quick' if merged.get('quick') else 'full'} run {when}\n{merged['machine']}"
    axes.set_title(title, fontsize=8)
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    plt.close(figure)


if __name__ == "__main__":
    main()
