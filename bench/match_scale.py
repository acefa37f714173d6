"""Benchmark: rank a pool of advertisements for one requirement, at the sizes issue 18 names.

The taxonomy, advertisements and requirements are synthetic and seeded (reasoner/synthetic.py). The
index and the pool's array layout are built once (``Matchmaker.prepare``, reported as set-up); what is
timed is ``Matchmaker.rank`` for one requirement: the whole pool scored and ordered (the first
``--explain`` candidates are explained when they are read: a second figure times the ranking with those
explanations read, as `cbrs match` and the bridge read them).

Without ``--json`` it runs one configuration (the options below). With ``--json FILE`` it runs the rows
of issue 18 and writes them as a list of records ``{row, value, anchor, ratio, unit, goal, met}``:

- one requirement against 10,000 and 100,000 advertisements over 4,000 classes (p50 <= 10 ms, <= 50 ms);
- 10,000 advertisements over a taxonomy of 64,000 classes (p50 <= 40 ms);
- the strict logic baseline and sem-str on the OWLS-TC 4 development part, mean per query (<= 10 ms,
  <= 5 ms; skipped when ``--owls-tc`` is not a folder).

The anchor of a synthetic row is measured in the same run: the least work any ranker of that pool does,
one similarity lookup per advertised output, a mean per advertisement and a sort of the pool (numpy). The
anchor of an OWLS-TC row is the same queries ranked by pure string matching. The ratio is value / anchor;
the goal is on the value, as the issue states it.

Run: python bench/match_scale.py [--classes 4000] [--ads 10000] [--queries 20] [--method sem-str]
     python bench/match_scale.py --json FILE [--quick] [--owls-tc ../shared/owls-tc4]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

from cbrs.kb import Advertisement, KnowledgeBase, Requirement, Store
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.synthetic import build

ROOT = Path(__file__).resolve().parents[1]
OWLS_TC = ROOT.parent / "shared" / "owls-tc4"


def _timed_ranks(
    matchmaker: Matchmaker, requirements: list[Requirement] | list[str], explain: int, cpu: list[float] | None = None
) -> tuple[list[float], list[float]]:
    """ms per ranking, and per ranking with the first ``explain`` candidates' explanations then read (a
    ranking explains a candidate when it is first read, as `cbrs match` and the bridge read them).
    ``cpu`` receives each ranking's CPU ms (this thread's), less sensitive than wall time to other work
    on a shared machine."""
    ranked, read = [], []
    for requirement in requirements:
        begin, begin_cpu = time.perf_counter(), time.thread_time()
        result = matchmaker.rank(requirement, explain=explain)
        ranked.append((time.perf_counter() - begin) * 1000)
        if cpu is not None:
            cpu.append((time.thread_time() - begin_cpu) * 1000)
        assert all(c.explained for c in result.candidates[:explain])
        read.append((time.perf_counter() - begin) * 1000)
        assert len(result.candidates) == len(matchmaker.advertisements)
    return ranked, read


def _anchor(pool: list[Advertisement], requirements: list[Requirement]) -> float:
    """p50 ms of the least a ranker of this pool does: a lookup per advertised output in a similarity
    row, the mean per advertisement, a sort."""
    concepts = sorted({p.type for ad in pool for p in ad.outputs} | {p.type for r in requirements for p in r.outputs})
    ids = {c: i for i, c in enumerate(concepts)}
    flat = np.array([ids[p.type] for ad in pool for p in ad.outputs], dtype=np.int64)
    counts = np.array([len(ad.outputs) for ad in pool], dtype=np.int64)
    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    rng = np.random.default_rng(7)
    samples = []
    for _ in requirements:
        row = rng.random(len(concepts))  # stands for one requirement's similarity row
        begin = time.perf_counter()
        scores = np.add.reduceat(row[flat], starts) / counts
        np.argsort(-scores, kind="stable")
        samples.append((time.perf_counter() - begin) * 1000)
    return statistics.median(samples)


def synthetic_row(name: str, classes: int, ads: int, queries: int, goal: float, explain: int) -> dict[str, Any]:
    start = time.perf_counter()
    index, pool, requirements = build(classes, ads, queries, seed=7)
    matchmaker = Matchmaker(KnowledgeBase(Store.open(":memory:")), index=index, advertisements=pool).prepare()
    setup = time.perf_counter() - start
    cpu: list[float] = []
    samples, explained = _timed_ranks(matchmaker, requirements, explain, cpu)
    read = statistics.median(explained)
    value, anchor = statistics.median(samples), _anchor(pool, requirements)
    p90 = sorted(samples)[int(len(samples) * 0.9) - 1]
    print(
        f"  {name}: set-up {setup:.1f} s; p50 {value:.1f} ms (CPU {statistics.median(cpu):.1f} ms), p90 {p90:.1f} ms,"
        f" anchor {anchor:.2f} ms; with the first {explain} explanations read, p50 {read:.1f} ms",
        flush=True,
    )
    return _record(name, value, anchor, "ms", goal)


def owls_tc_rows(folder: Path) -> list[dict[str, Any]]:
    from cbrs.reasoner.owlstc import _file_key, load_collection, read_relevance

    judgements = read_relevance(folder / "relevance.xml")
    loaded = load_collection(folder)
    queries = [iris[0] for uri in judgements.binary if (iris := loaded.requirements.get(_file_key(uri)))]
    means = {}
    first: Matchmaker | None = None
    for method in ("string", "logic", "sem-str"):
        if first is None:
            matchmaker = first = Matchmaker(loaded.kb, method)
        else:
            matchmaker = Matchmaker(loaded.kb, method, index=first.index, advertisements=first.advertisements)
        matchmaker.prepare()  # as `cbrs eval owls-tc` does: reading the pool is loading
        means[method] = statistics.fmean(_timed_ranks(matchmaker, queries, explain=0)[0])
        print(f"  OWLS-TC dev, {method}: mean {means[method]:.2f} ms per query ({len(queries)} queries)", flush=True)
    return [
        _record("OWLS-TC dev, logic baseline, mean per query", means["logic"], means["string"], "ms", 10),
        _record("OWLS-TC dev, sem-str, mean per query", means["sem-str"], means["string"], "ms", 5),
    ]


def _record(row: str, value: float, anchor: float | None, unit: str, goal: float) -> dict[str, Any]:
    ratio = round(value / anchor, 2) if anchor else None
    anchor_value = round(anchor, 3) if anchor is not None else None
    return {
        "row": row,
        "value": round(value, 2),
        "anchor": anchor_value,
        "ratio": ratio,
        "unit": unit,
        "goal": f"<= {goal:g}",
        "met": value <= goal,
    }


def rows(quick: bool, owls_tc: Path) -> list[dict[str, Any]]:
    queries = 5 if quick else 20
    found = [
        synthetic_row("rank 10,000 ads (4,000 classes), p50", 4000, 10_000, queries, 10, explain=10),
        synthetic_row("rank 100,000 ads (4,000 classes), p50", 4000, 100_000, queries, 50, explain=10),
        synthetic_row("rank 10,000 ads over 64,000 classes, p50", 64_000, 10_000, queries, 40, explain=10),
    ]
    if (owls_tc / "relevance.xml").exists():
        found += owls_tc_rows(owls_tc)
    else:
        print(f"  {owls_tc}: no OWLS-TC collection there, its rows are skipped")
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--classes", type=int, default=4000)
    parser.add_argument("--ads", type=int, default=10000)
    parser.add_argument("--queries", type=int, default=20)
    parser.add_argument("--method", choices=METHODS, default="sem-str")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--explain", type=int, default=10, help="candidates explained in full")
    parser.add_argument("--json", type=Path, help="run the issue-18 rows and write their records here")
    parser.add_argument("--quick", action="store_true", help="with --json: 5 requirements per row instead of 20")
    parser.add_argument("--owls-tc", type=Path, default=OWLS_TC, help="the OWLS-TC 4 development part")
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
        f", load average {os.getloadavg()[0]:.2f}"
    )
    if args.json is not None:
        records = rows(args.quick, args.owls_tc)
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(records, indent=2) + "\n", encoding="utf-8")
        for record in records:
            verdict = "met" if record["met"] else "NOT met"
            print(f"{record['row']:<48} {record['value']:>8} {record['unit']}  goal {record['goal']:<6} {verdict}")
        return
    print(
        f"inputs: {args.classes} classes, {args.ads} advertisements, {args.queries} requirements, "
        f"method {args.method}, seed {args.seed}"
    )
    start = time.perf_counter()
    index, pool, requirements = build(args.classes, args.ads, args.queries, args.seed)
    kb = KnowledgeBase(Store.open(":memory:"))
    matchmaker = Matchmaker(kb, args.method, index=index, advertisements=pool).prepare()
    print(f"setup (taxonomy index, pool, prepare): {time.perf_counter() - start:.2f} s; index has {len(index)} nodes")
    cpu: list[float] = []
    samples, explained = _timed_ranks(matchmaker, requirements, args.explain, cpu)
    ordered = sorted(samples)
    print(
        f"rank all {args.ads} (top {args.explain} explained when read), over {len(samples)} requirements: "
        f"p50 {statistics.median(samples):.1f} ms (CPU {statistics.median(cpu):.1f} ms), "
        f"p90 {ordered[int(len(ordered) * 0.9) - 1]:.1f} ms, max {ordered[-1]:.1f} ms "
        f"(first requirement {samples[0]:.1f} ms)"
    )
    read = sorted(explained)
    print(
        f"the same, reading the top {args.explain} explanations: p50 {statistics.median(read):.1f} ms, "
        f"p90 {read[int(len(read) * 0.9) - 1]:.1f} ms"
    )


if __name__ == "__main__":
    main()
