"""A run followed from a notebook (the tenth round, docs/tasks.md "A tenth round"): the library alone, as
docs/execution.md "A task run from Python" shows it, with ``run_task``'s ``on_event`` (its docstring) to
print each event as the run goes, one cell's worth of code. The store must hold the travel mug
(lab10_travel_mug.ttl in the ontology and the map, lab10_travel_mug_is_a_cup.ttl in the ontology) and
lab10_fill_my_travel_mug.ttl in the requirements:

    python docs/examples/lab10_watch_a_run.py --store DIR [--seed N] [--task FillMyTravelMug]
    CBRS_UPDATE_TOKEN=secret python docs/examples/lab10_watch_a_run.py --store http://127.0.0.1:8080

A store by its URL (a cbrs serve's) is written with the server's update token, which the program passes
itself (``remote_token``): the library reads no CBRS_UPDATE_TOKEN, the cbrs command does.

It prints one line per event as it comes (the topic, then the message's fields) on standard error, where a
notebook shows it as well, and then one line of JSON on standard output: the task, succeeded, sim_seconds,
the number of events by topic and the steps in the order they ended.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections import Counter

from cbrs.actions import run_task
from cbrs.actions.events import Event
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import HomeWorld
from cbrs.sim.components import SimEnvironment

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("--store", required=True)
parser.add_argument("--seed", type=int, default=0)
parser.add_argument("--task", default="FillMyTravelMug")
args = parser.parse_args()

topics: Counter[str] = Counter()
ended: list[str] = []


def watch(event: Event) -> None:
    """What a notebook cell would show as the run goes."""
    topics[event.topic] += 1
    message = event.message
    print(event.topic, {k: v for k, v in message.items() if v not in (None, "", [], {})}, file=sys.stderr, flush=True)
    if message.get("event") in ("step_succeeded", "step_failed"):  # docs/serving.md, the bridge's topics
        ended.append(f"{message['step']} {str(message['component']).rsplit('#', 1)[-1]} {message['event'][5:]}")


remote = args.store.startswith(("http://", "https://"))
kb = KnowledgeBase.open(args.store, remote_token=os.environ.get("CBRS_UPDATE_TOKEN") if remote else None)
with HomeWorld.create(seed=args.seed, semantic_map=SemanticMap.read(kb)) as world:
    result = run_task(kb, args.task, SimEnvironment(world, kb), on_event=watch)
    seconds = world.time
kb.close()
print(
    json.dumps(
        {
            "task": args.task,
            "succeeded": result.succeeded,
            "sim_seconds": round(seconds, 1),
            "events": dict(topics),
            "steps": ended,
        }
    )
)
