"""A seventh-round trial (docs/tasks.md, "A seventh round"): "where is my pen?" asked from a Python
program through cbrs's library, no CLI and no server.

It opens a store of its own, writes the task with the same SPARQL update as lab7_where_is_my_pen.ru
(KnowledgeBase.update, checked as /update checks it), runs it in the simulated home
(actions.runner.run_task with sim.components.SimEnvironment over a HomeWorld built from the store's
map, as docs/architecture.md, execution.md and simulation.md name them) and prints the answer,
RunResult.answers (execution.md, "Answers"):

    python docs/examples/lab7_where_is_my_pen.py --store /tmp/lab7-store --seed 0
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import HomeWorld
from cbrs.sim.components import SimEnvironment

HERE = Path(__file__).resolve().parent
TASK = "WhereIsMyPen"


def ask(kb: KnowledgeBase, seed: int) -> dict:
    """Run the task once; the pen's position as the Kinect saw it, and how the run went."""
    with HomeWorld.create(seed=seed, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, TASK, SimEnvironment(world, kb))
        seconds = world.time
    answers = {answer.name: answer.value for answer in result.answers}
    return {"succeeded": result.succeeded, "sim_seconds": round(seconds, 1), "answers": answers}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--store", default=":memory:")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    kb = KnowledgeBase.open(args.store)
    if not kb.query("ASK { ?task <https://w3id.org/cbrs/core#serviceName> 'WhereIsMyPen' }"):
        kb.update((HERE / "lab7_where_is_my_pen.ru").read_text())
    print(json.dumps(ask(kb, args.seed), indent=1))


if __name__ == "__main__":
    main()
