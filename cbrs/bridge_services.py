"""The knowledge base as rosbridge services and topics, for non-ROS nodes and web pages.

Services (request fields -> response values):

- ``/cbrs/query`` ``{query}`` -> ``{media_type, result}``: SPARQL JSON results for SELECT/ASK, JSON-LD
  for CONSTRUCT/DESCRIBE; read-only, with the endpoint's timeout and size limit.
- ``/cbrs/match`` ``{requirement, method="sem-str", top=10}`` -> the ranking with explanations.
- ``/cbrs/plan`` ``{task, objective="similarity"}`` -> the plan (recorded in the plans graph when the
  caller may write) or what is unsatisfied.
- ``/cbrs/run_task`` ``{task, seed=0, fail=[], wait=true}`` -> the run; with ``wait`` false it returns
  at once and the run is followed on the topics, or with ``/cbrs/task_status`` ``{run}``.

Anonymous clients only read: recording a plan and running a task write the store, so they need a
caller that sent the update token (op ``auth``) or a page of this server's own (its handshake's
``Origin``). The topics below belong to the server; clients cannot advertise or publish them.

Topics: ``/cbrs/task_progress`` (steps started, succeeded, failed, with failovers), ``/cbrs/lifecycle``
(component states), ``/cbrs/task`` (a run's verdict) and ``/cbrs/events`` (runs starting and ending,
store updates).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Collection
from typing import TYPE_CHECKING, Any, TypeVar

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import GraphName, expand
from cbrs.kb.store import is_remote
from cbrs.matchmakers import Matchmakers
from cbrs.reasoner.methods import METHODS
from cbrs.rosbridge import Bridge, ServiceError, current_caller
from cbrs.sparql_service import SparqlService
from cbrs.tasks import RUN_TOPIC, TaskRunner

if TYPE_CHECKING:
    from cbrs.actions.composer import Composer, Objective

TOPICS = {
    "/cbrs/task_progress": "cbrs/TaskProgress",
    "/cbrs/lifecycle": "cbrs/LifecycleState",
    "/cbrs/task": "cbrs/TaskStatus",
    RUN_TOPIC: "cbrs/Event",
}

T = TypeVar("T")
Handler = Callable[[dict[str, Any]], dict[str, Any]]


class KnowledgeServices:
    """Request handlers over one knowledge base."""

    def __init__(
        self,
        sparql: SparqlService,
        tasks: TaskRunner,
        matchmakers: Matchmakers | None = None,
        own_origins: Callable[[], Collection[str]] = lambda: (),
    ) -> None:
        self.sparql = sparql
        self.tasks = tasks
        self.matchmakers = matchmakers or Matchmakers(sparql)
        self.composers = Composers(sparql)
        self.own_origins = own_origins

    def may_write(self) -> bool:
        """Whether the client whose call is answered may write: it sent the token, or it is one of this
        server's pages. A call from this process (no bridge client) may."""
        caller = current_caller()
        if caller is None or caller.authorised:
            return True
        return caller.origin is not None and caller.origin.rstrip("/") in self.own_origins()

    def handlers(self) -> dict[str, tuple[str, Handler]]:
        """Service name -> (type, handler)."""
        return {
            "/cbrs/query": ("cbrs/Query", self.query),
            "/cbrs/match": ("cbrs/Match", self.match),
            "/cbrs/plan": ("cbrs/Plan", self.plan),
            "/cbrs/run_task": ("cbrs/RunTask", self.run_task),
            "/cbrs/task_status": ("cbrs/TaskStatus", self.task_status),
        }

    def query(self, args: dict[str, Any]) -> dict[str, Any]:
        text = _field(args, "query", str)
        caller = current_caller()
        client = caller.peer if caller is not None else None
        answer = _call(lambda: self.sparql.query(text, short_format="json", client=client))
        return {"media_type": answer.media_type, "result": json.loads(answer.body)}

    def match(self, args: dict[str, Any]) -> dict[str, Any]:
        requirement = _iri(_field(args, "requirement", str), "req")
        method = _field(args, "method", str, "sem-str")
        top = _field(args, "top", int, 10)
        if method not in METHODS:
            raise ServiceError(f"method {method!r} is not one of {', '.join(METHODS)}")
        if top < 1:
            raise ServiceError(f"top must be at least 1, not {top}")
        with self.sparql.lock:
            matchmaker = self.matchmakers.get(method)
            result = _call(lambda: matchmaker.rank(requirement, explain=top))
        return result.to_dict(top)

    def plan(self, args: dict[str, Any]) -> dict[str, Any]:
        from cbrs.actions.composer import Objective, store_plan  # the planner loads with the first plan

        task = _field(args, "task", str)
        objective = _field(args, "objective", str, Objective.SIMILARITY.value)
        if objective not in {o.value for o in Objective}:
            raise ServiceError(f"objective {objective!r} is not one of {', '.join(o.value for o in Objective)}")
        with self.sparql.lock:
            composer = self.composers.get(Objective(objective))
            result = _call(lambda: composer.compose(task))
            recorded = result.plan is not None and not self.sparql.config.read_only and self.may_write()
            if result.plan is not None and recorded:
                store_plan(self.sparql.kb, result.plan)
        return {**result.to_dict(), "recorded": recorded}

    def run_task(self, args: dict[str, Any]) -> dict[str, Any]:
        task = _field(args, "task", str)
        seed = _field(args, "seed", int, 0)
        faults = _field(args, "fail", list, [])
        wait = _field(args, "wait", bool, True)
        rate = args.get("fault_rate", 0.0)
        if not all(isinstance(f, str) for f in faults):
            raise ServiceError("fail must be a list of component IRIs (strings)")
        if isinstance(rate, bool) or not isinstance(rate, (int, float)):
            raise ServiceError(f"field 'fault_rate' must be a number in [0, 1], not {type(rate).__name__}")
        if not self.may_write() and not self.sparql.config.read_only:  # a read-only server says so itself
            raise ServiceError(
                "a task run moves the robot and writes the store: send the update token first "
                '({"op": "auth", "mac": "<token>"}), or start it from this server\'s tasks page'
            )
        if wait:
            run = _call(lambda: self.tasks.run(task, seed, faults, fault_rate=float(rate)))
        else:
            run = _call(lambda: self.tasks.start(task, seed, faults, float(rate)))
        return run.to_dict(with_events=False)

    def task_status(self, args: dict[str, Any]) -> dict[str, Any]:
        run_id = _field(args, "run", str)
        return _call(lambda: self.tasks.get(run_id)).to_dict()


class Composers:
    """Composers kept between /cbrs/plan calls, one per objective, sharing the taxonomy index, the
    action library and the advertisements (building them is most of a call's time).

    They are made again when the store changes: an update through the endpoint or a component
    registered or leaving (``SparqlService.generation``), a component whose lease lapsed (the set of
    unavailable components), and on a remote store, other processes' writes (the sizes of the
    ontology and services graphs). Call ``get`` and compose with the knowledge-base lock held: a
    composer is not safe for two compositions at once.
    """

    def __init__(self, sparql: SparqlService) -> None:
        self.sparql = sparql
        self._version: object = None
        self._built: dict[Objective, Composer] = {}

    def get(self, objective: Objective) -> Composer:
        from cbrs.actions.composer import ComposeConfig, Composer

        kb = self.sparql.kb
        version: tuple[object, ...] = (self.sparql.generation, frozenset(kb.liveness.unavailable()))
        if is_remote(kb.store.location):
            version += (kb.store.count(GraphName.ONTOLOGY), kb.store.count(GraphName.SERVICES))
        if version != self._version:
            self._version, self._built = version, {}
        composer = self._built.get(objective)
        if composer is None:
            shared = next(iter(self._built.values()), None)
            composer = Composer(
                kb,
                ComposeConfig(objective=objective),
                index=shared.index if shared is not None else None,
                actions=shared.actions if shared is not None else None,
                advertisements=shared.advertisements if shared is not None else None,
            )
            self._built[objective] = composer
        return composer


def attach(bridge: Bridge, services: KnowledgeServices) -> Callable[[], None]:
    """Offer ``services`` on ``bridge`` and relay task events to its topics; returns the detach call."""
    for name, (kind, handler) in services.handlers().items():
        bridge.add_service(name, kind, handler)
    for topic, kind in TOPICS.items():
        bridge.add_topic(topic, kind)

    def relay(topic: str, message: dict[str, Any]) -> None:
        if topic in TOPICS:
            bridge.publish(topic, message)

    unsubscribe_tasks = services.tasks.subscribe(relay)
    unsubscribe_store = services.sparql.on_update(lambda: bridge.publish(RUN_TOPIC, {"event": "store_updated"}))

    def detach() -> None:
        unsubscribe_tasks()
        unsubscribe_store()

    return detach


def _field(args: dict[str, Any], name: str, kind: type, default: Any = ...) -> Any:
    if name not in args or args[name] is None:
        if default is ...:
            raise ServiceError(f"missing field {name!r}")
        return default
    value = args[name]
    if (kind is int and isinstance(value, bool)) or not isinstance(value, kind):
        raise ServiceError(f"field {name!r} must be {kind.__name__}, not {type(value).__name__}")
    return value


def _iri(name: str, default_prefix: str) -> str:
    try:
        return expand(name if ":" in name else f"{default_prefix}:{name}")
    except ValueError as error:
        raise ServiceError(str(error)) from error


def _call(work: Callable[[], T]) -> T:
    """Run ``work``; a library error becomes the service error the caller sees (result false)."""
    try:
        return work()
    except (KnowledgeBaseError, ValueError) as error:
        raise ServiceError(str(error)) from error
