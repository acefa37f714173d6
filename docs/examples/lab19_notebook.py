"""lab19 (docs/architecture.md, "Tried by a researcher from Python"): cbrs as a library, cell by cell, the
way a robotics researcher uses it from a notebook. An in-memory store gets the lab's own object kind and
place (lab19_vial_and_rack.ttl) and requests (lab19_vial_tasks.ttl); it is queried with SPARQL and a
named query, a request is ranked by the paper's Sem-Str and the string baseline, a task is planned and
inspected (steps, bindings, why another has no plan), the lab's mistakes are caught by their typed
exceptions (the store left as it was), two threads share the store, the task runs in the simulated home
headless, and an on-disk store is opened, used, closed and reopened. Run from the checkout:
    python docs/examples/lab19_notebook.py
"""

from __future__ import annotations

import tempfile
import threading
from pathlib import Path

from cbrs.actions import Composer, UnknownTaskError, run_task
from cbrs.kb import (
    DescriptionShapeError,
    KnowledgeBase,
    MapError,
    QuerySyntaxError,
    RdfParseError,
    StoreInUseError,
)
from cbrs.kb.semantic_map import SemanticMap
from cbrs.reasoner import MatchConfig, Matchmaker
from cbrs.sim import HomeWorld
from cbrs.sim.components import SimEnvironment

HERE = Path(__file__).resolve().parent
VIAL_AND_RACK = HERE / "lab19_vial_and_rack.ttl"
TASKS = HERE / "lab19_vial_tasks.ttl"
LAB19 = "https://example.org/lab19#"


def load_the_lab(kb: KnowledgeBase) -> None:
    """The lab's class and place into the ontology and the map, its requests into the requirements."""
    for path, graph in ((VIAL_AND_RACK, "ontology"), (VIAL_AND_RACK, "map"), (TASKS, "requirements")):
        report = kb.load([path], graph=graph)
        print(f"loaded {path.name} into {graph}: {sum(report.added.values())} triples added")


# -- a throw-away store in memory, seeded with the bundled home ------------------------------------------
kb = KnowledgeBase.open(":memory:")
print(kb)
load_the_lab(kb)

# -- SPARQL, and a named query with bound values ---------------------------------------------------------
rows = kb.query("SELECT DISTINCT ?kind WHERE { ?kind rdfs:subClassOf home:Container } ORDER BY ?kind")
print("containers:", ", ".join(row["kind"].value.rsplit("#", 1)[-1] for row in rows))
for row in kb.select("things_in_room", {"class": "home:Container", "room": "world:Kitchen"}):
    print(f"in the kitchen: {row['thing'].value} at ({float(row['x'].value):.2f}, {float(row['y'].value):.2f})")

# -- ranking services for the lab's request: Sem-Str and the string baseline ----------------------------
for method in ("sem-str", "string"):
    ranking = Matchmaker(kb, method, MatchConfig()).rank(LAB19 + "LocateMyVial", explain=3)
    print(f"LocateMyVial by {method}: {ranking.status.value}")
    for candidate in ranking.candidates[:3]:
        pairs = ", ".join(f"{p.role} {p.shown_degree()} {p.similarity:.2f}" for p in candidate.pairs)
        print(f"  {candidate.score:.3f} {candidate.label} ({pairs})")

# -- a plan, step by step, and a task without one -------------------------------------------------------
composed = Composer(kb).compose("PutVialInRack")
plan = composed.plan
assert plan is not None, [need.text() for need in composed.unsatisfied]
print(plan)
for step in plan.steps:
    print(" ", step)
print("goals:", plan.goals)
refused = Composer(kb).compose("ShakeMyVial")
print(f"ShakeMyVial: {refused.status.value}")
for need in refused.unsatisfied:
    print("  why:", need.text())

# -- mistakes, each caught by its type, and the store as it was -----------------------------------------
before = kb.statistics()
SLIP = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix svc: <https://w3id.org/cbrs/service#> . @prefix lab19: <https://example.org/lab19#> .
lab19:PutVialBack a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "PutVialBack" ; cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "vial" ; cbrs:parameterType lab19:SampleViall ] ] .
"""
with tempfile.TemporaryDirectory() as scratch:
    slip = Path(scratch) / "put_vial_back.ttl"
    slip.write_text(SLIP, "utf-8")
    try:
        kb.load([slip], graph="requirements")
    except DescriptionShapeError as error:
        print("misspelt class:", str(error).split(": ", 1)[1])
try:
    kb.query("SELECT ?kind WHERE { ?kind rdfs:subClassOf home:Container ")
except QuerySyntaxError as error:
    print("bad query:", error.message, "in", repr(error.query[-20:]))
try:
    kb.load([HERE / "lab19_no_such_file.ttl"], graph="map")
except RdfParseError as error:
    print("missing file:", Path(error.source).name, error.message)
MOVE_THE_VIAL = """
DELETE { GRAPH graph:map { ?vial home:x ?x } } INSERT { GRAPH graph:map { ?vial home:x 9.0 } }
WHERE { GRAPH graph:map { ?vial a lab19:SampleVial ; home:x ?x } }"""
try:
    kb.update("PREFIX lab19: <https://example.org/lab19#>" + MOVE_THE_VIAL)  # off the table's far edge
except MapError as error:
    print("failed update:", str(error).split(": ", 1)[1])
try:
    Composer(kb).compose("PutVialInRak")
except UnknownTaskError as error:
    print("unknown task:", error.name, "- PutVialInRack known:", "PutVialInRack" in error.known)
print("store as it was:", kb.statistics() == before)

# -- two threads on one store: a named query and a composition at once ----------------------------------
found: dict[str, object] = {}
threads = [
    threading.Thread(target=lambda: found.update(rows=len(kb.select("things_in_room", {"class": "home:Container"})))),
    threading.Thread(target=lambda: found.update(plan=Composer(kb).compose("PutVialInRack").status.value)),
]
for thread in threads:
    thread.start()
for thread in threads:
    thread.join()
print("two threads:", found["rows"], "containers,", found["plan"])

# -- the task in the simulated home, headless -----------------------------------------------------------
progress: list[str] = []


def follow(event: object) -> None:
    message = getattr(event, "message", {})
    if getattr(event, "topic", "") == "/cbrs/task_progress" and message.get("event") == "step_succeeded":
        progress.append(f"{message['step']}")


with HomeWorld.create(seed=0, semantic_map=SemanticMap.read(kb)) as world:
    result = run_task(kb, "PutVialInRack", SimEnvironment(world, kb), on_event=follow)
    seconds = world.time
verdict = "succeeded" if result.succeeded else "failed"
print(f"run: {verdict} in {seconds:.1f} simulated s; steps done: {', '.join(progress)}")
for goal in result.goals:
    print(f"  goal {goal.statement.predicate.rsplit('#', 1)[-1]}: believed {goal.believed}, holds {goal.holds}")
kb.close()

# -- on disk: opened in a with block, closed, reopened --------------------------------------------------
with tempfile.TemporaryDirectory() as folder:
    with KnowledgeBase.open(folder) as lab:
        print(lab)
        load_the_lab(lab)
        stored = lab.statistics()
        try:
            KnowledgeBase.open(folder)  # a second open while the first holds the lock
        except StoreInUseError as error:
            print("opened twice:", error.location == folder)
    with KnowledgeBase.open(folder) as lab:  # the with block closed it: the lock is free again
        print("reopened:", lab.statistics() == stored, Composer(lab).compose("PutVialInRack").status.value)
