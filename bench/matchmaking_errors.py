"""Error analysis of a matching method on an OWLS-TC style collection: per query, which relevant services
rank low, what outranks them, and which part of the score decided it.

For every judged query it prints the average precision; the first services judged not relevant that rank
above the last relevant one (the "intruders"); and each relevant service ranked below the R-th place (R =
the number of relevant services: where a perfect ranking would have put the last one), each with its
rank, score and score parts. What docs/matchmaking.md's error analysis is written from.

Run: python bench/matchmaking_errors.py FOLDER [--method sem-str] [--set name=value ...] [--intruders 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import statistics
from pathlib import Path
from typing import Any

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Candidate, Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.metrics import average_precision
from cbrs.reasoner.names import local_name
from cbrs.reasoner.owlstc import _file_key, load_collection, read_relevance


def _config(settings: list[str]) -> MatchConfig:
    """MatchConfig with ``name=value`` overrides, each value read as the field's type."""
    fields = {f.name: f for f in dataclasses.fields(MatchConfig)}
    values: dict[str, Any] = {}
    for item in settings:
        name, _, text = item.partition("=")
        if name not in fields:
            raise SystemExit(f"unknown MatchConfig field {name!r}; fields: {', '.join(fields)}")
        default = getattr(MatchConfig(), name)
        values[name] = text.lower() in ("1", "true", "yes") if isinstance(default, bool) else type(default)(text)
    return dataclasses.replace(MatchConfig(), **values)


def _line(rank: int, candidate: Candidate, relevant: bool) -> str:
    parts = " ".join(f"{name}={value:.2f}" for name, value in candidate.parts.items())
    mark = "R" if relevant else "-"
    return f"  {rank:5d} {mark} {candidate.score:.3f} {local_name(candidate.advertisement)[:48]:48s} {parts}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path)
    parser.add_argument("--method", choices=METHODS, default="sem-str")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a MatchConfig override")
    parser.add_argument("--intruders", type=int, default=3, help="services not relevant shown per query")
    args = parser.parse_args()
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    judgements = read_relevance(args.folder / "relevance.xml")
    loaded = load_collection(args.folder)
    matcher = Matchmaker(loaded.kb, args.method, _config(args.set)).prepare()
    print(f"{args.folder}: method {args.method}, overrides {args.set or 'none'}")
    aps = []
    for uri, rated in judgements.binary.items():
        iris = loaded.requirements.get(_file_key(uri), [])
        if not iris:
            continue
        relevant = {a for offer, v in rated.items() if v for a in loaded.advertisements.get(_file_key(offer), [])}
        ranking = list(matcher.rank(iris[0], explain=0).candidates)
        order = [c.advertisement for c in ranking]
        ap = average_precision(order, relevant)
        aps.append(ap)
        print(f"\n## {local_name(iris[0])}: AP {ap:.3f}, {len(relevant)} relevant")
        misses = [(r, c) for r, c in enumerate(ranking, start=1) if c.advertisement in relevant and r > len(relevant)]
        if not misses:
            continue
        intruders = [(r, c) for r, c in enumerate(ranking[: misses[-1][0]], start=1) if c.advertisement not in relevant]
        print(f"  not relevant, ranked above the last relevant ({len(intruders)}; first {args.intruders}):")
        for rank, candidate in intruders[: args.intruders]:
            print(_line(rank, candidate, False))
        print(f"  relevant, ranked below place {len(relevant)} ({len(misses)}):")
        for rank, candidate in misses:
            print(_line(rank, candidate, True))
    print(f"\nMAP {statistics.fmean(aps):.4f} over {len(aps)} queries")


if __name__ == "__main__":
    main()
