"""The knowledge base as rosbridge services and topics, for non-ROS nodes and web pages.

Services (request fields -> response values):

- ``/cbrs/query`` ``{query}`` -> ``{media_type, result}``: SPARQL JSON results for SELECT/ASK, JSON-LD
  for CONSTRUCT/DESCRIBE; read-only, with the endpoint's timeout and size limit.
- ``/cbrs/match`` ``{requirement, method="sem-str", top=10}`` -> the ranking with explanations.
- ``/cbrs/plan`` ``{task, objective="similarity", base_ties="nearest", near_misses=3}`` -> the plan (recorded
  in the plans graph when the caller may write) or what is unsatisfied, with as many near misses named per
  unmet need as ``near_misses`` asks (-1: the default, 0: none), as ``cbrs plan --near-misses``; in a home
  of several mobile bases the plan works one, chosen as ``cbrs plan`` and a run choose it, and ``base`` says
  which and why (``BaseChoice.to_dict``).

Each type is defined in ``cbrs/interfaces`` (``srv/Match.srv``, ``msg/Candidate.msg``...), which rosapi's
details services describe. A ROS client fills every field of a request, an unset one with its type's
zero value: an empty ``method``, ``objective`` or ``base_ties`` and a ``top`` of 0 mean the default; not so
a ``near_misses`` of 0, which names none (-1 is its "not given").
- ``/cbrs/tasks`` ``{}`` -> ``{tasks}``: every task the store can express, as ``task`` takes it.
- ``/cbrs/run_task`` ``{task, seed=0, fail=[], fault_rate=0, repeat_failures=1, objective="similarity",
  base_ties="nearest", near_misses=3, wait=true}`` -> the run;
  with ``wait`` false it returns at once and the run is followed on the topics, or with
  ``/cbrs/task_status`` ``{run}``; with ``wait`` it answers when the run ends or, at the latest, two
  seconds before the bridge's call timeout, with the run as it is then (``running``, or ``queued`` with its
  ``position`` while it waits for the run going: the ``run_queue`` setting). ``task`` is any
  requirement or action of the store, named as ``cbrs run`` takes it; ``repeat_failures`` as
  ``cbrs run --repeat-failures``; ``objective``, ``base_ties`` and ``near_misses`` as ``cbrs run
  --objective --base-ties --near-misses``, checked by ``TaskRunner.start`` as ``POST /tasks`` checks them:
  an empty ``objective`` or ``base_ties`` and a ``near_misses`` of -1 (what a ROS client sends for "not
  given"; its zero, 0, asks for none) mean ``cbrs run``'s default. Its ``result`` holds ``answers``: the
  values of the outputs the task asks for (a room's temperature), with the component that gave each
  (docs/execution.md, "Answers").

Action (rosbridge's ROS 2 action ops, ``send_action_goal`` and the rest):

- ``/cbrs/run_task`` (type ``cbrs/action/RunTask``), goal ``{task, seed=0, fail=[], fault_rate=0,
  repeat_failures=1, objective="similarity", base_ties="nearest", near_misses=3}`` (read as the service
  reads them):
  one feedback ``{run, iri, shown, plan, step, action, component, status, reason, failover}`` per plan
  step that ends (``status`` succeeded or failed; ``iri`` and ``shown`` name the run's task as its result
  does); the result is the run as the service returns it, with status
  SUCCEEDED, CANCELED (the client cancelled: the run stops after the step under way, or at once during a
  remote call, which it abandons: docs/execution.md) or ABORTED (the
  run failed, found no plan or broke). A goal sent while a run goes waits in the runner's queue when it has
  room (``run_queue``): its first feedback has ``status`` ``queued`` (``reason`` says its place in line), one
  with ``status`` ``running`` follows when it starts, and a cancel meanwhile takes it out of the queue
  (CANCELED, the run ``cancelled`` with its ``reason``). A refused goal (no token, unknown task, a run going
  and no room to wait) fails as rosbridge fails a goal: ``result: false``, status UNKNOWN, the reason as
  ``values``.

Anonymous clients only read: recording a plan and running a task write the store, so they need a
caller that sent the update token (op ``auth``) or a page of this server's own (its handshake's
``Origin``). The topics below belong to the server; clients cannot advertise or publish them.

Topics: ``/cbrs/task_progress`` (steps started, succeeded, failed, with failovers), ``/cbrs/lifecycle``
(component states), ``/cbrs/task`` (a run's verdict) and ``/cbrs/events`` (runs starting and ending,
store updates). A run's messages and the answers about a run all carry its task's ``iri`` and ``shown`` (as
the pages name it), beside a ``task`` whose meaning each kept (docs/rosbridge.md, "How a run names its task").
"""

from __future__ import annotations

import difflib
import json
import threading
from collections.abc import Callable, Collection
from dataclasses import replace
from importlib.resources import files
from typing import TYPE_CHECKING, Any, TypeVar

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import GraphName, expand
from cbrs.kb.store import is_remote
from cbrs.matchmakers import Matchmakers
from cbrs.rosbridge import Bridge, GoalHandle, GoalResult, GoalStatus, ServiceError, current_caller
from cbrs.rosbridge.session import TOKEN_REFUSED
from cbrs.sparql_service import SparqlService
from cbrs.tasks import RUN_TOPIC, TaskRun, TaskRunner, check_choice, check_near_misses, in_line

if TYPE_CHECKING:
    from cbrs.actions.composer import Composer, Objective

TOPICS = {
    "/cbrs/task_progress": "cbrs/TaskProgress",
    "/cbrs/lifecycle": "cbrs/LifecycleState",
    "/cbrs/task": "cbrs/TaskStatus",
    RUN_TOPIC: "cbrs/Event",
}

#: The services offered: name -> type (defined in INTERFACES, as the topics' types are).
SERVICES = {
    "/cbrs/query": "cbrs/Query",
    "/cbrs/match": "cbrs/Match",
    "/cbrs/plan": "cbrs/Plan",
    "/cbrs/run_task": "cbrs/RunTask",
    "/cbrs/tasks": "cbrs/Tasks",
    "/cbrs/task_status": "cbrs/TaskStatus",
}

#: The actions offered: name -> type. /cbrs/run_task is also a service; ROS 2 keeps the two apart.
ACTIONS = {"/cbrs/run_task": "cbrs/action/RunTask"}

#: A run's end status (TaskRun.status) -> the action goal's status; anything else aborted the goal.
GOAL_STATUS = {"succeeded": GoalStatus.SUCCEEDED, "cancelled": GoalStatus.CANCELED}

#: The fields each service (and the run_task action's goal) reads. Another is refused, as rosbridge refuses
#: a field its message type lacks: a misspelt optional one ("metod") was ignored and the default used.
_RUN = ("task", "seed", "fail", "fault_rate", "repeat_failures", "objective", "base_ties", "near_misses")

#: How a request says "not given" for a run's composition option (a ROS client fills every field): the
#: option is left to ``TaskRunner.start``'s default, ``cbrs run``'s. 0 near misses is a value (none).
_UNSET: dict[str, tuple[object, ...]] = {"objective": (None, ""), "base_ties": (None, ""), "near_misses": (None, -1)}
FIELDS: dict[str, tuple[str, ...]] = {
    "/cbrs/query": ("query",),
    "/cbrs/match": ("requirement", "method", "top"),
    "/cbrs/plan": ("task", "objective", "base_ties", "near_misses"),
    "/cbrs/run_task": (*_RUN, "wait"),
    "/cbrs/tasks": (),
    "/cbrs/task_status": ("run",),
}

#: The definitions of the services' and topics' types (one .msg/.srv file each), package ``cbrs``: what
#: rosapi's message_details and service_request/response_details describe.
INTERFACES = files("cbrs") / "interfaces"

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
        self.composers = Composers(sparql, self.matchmakers)
        self.own_origins = own_origins
        self.wait_limit = 28.0
        """Seconds ``/cbrs/run_task`` with ``wait`` waits for the run at most, then answers with the run as it
        is (``running``): under the bridge's call timeout, so a long run is no failed call (:func:`attach`)."""

    def may_write(self) -> bool:
        """Whether the client whose call is answered may write: it sent the token, or it is one of this
        server's pages. A call from this process (no bridge client) may."""
        caller = current_caller()
        if caller is None or caller.authorised:
            return True
        return caller.origin is not None and caller.origin.rstrip("/") in self.own_origins()

    def handlers(self) -> dict[str, tuple[str, Handler]]:
        """Service name -> (type, handler); each handler refuses a field its service does not read."""
        handlers: dict[str, Handler] = {
            "/cbrs/query": self.query,
            "/cbrs/match": self.match,
            "/cbrs/plan": self.plan,
            "/cbrs/run_task": self.run_task,
            "/cbrs/tasks": self.known_tasks,
            "/cbrs/task_status": self.task_status,
        }
        return {
            name: (SERVICES[name], _known_fields(name, FIELDS[name], handler)) for name, handler in handlers.items()
        }

    def query(self, args: dict[str, Any]) -> dict[str, Any]:
        text = _field(args, "query", str)
        caller = current_caller()
        client = caller.peer if caller is not None else None
        answer = _call(lambda: self.sparql.query(text, short_format="json", client=client))
        return {"media_type": answer.media_type, "result": json.loads(answer.body)}

    def match(self, args: dict[str, Any]) -> dict[str, Any]:
        requirement = _iri(_field(args, "requirement", str), "req")
        method = _field(args, "method", str, "") or "sem-str"  # "" and 0: what a ROS client sends for "unset"
        top = _field(args, "top", int, 0) or 10
        from cbrs.reasoner.methods import METHODS  # the reasoner loads with the first match, not at start-up

        if method not in METHODS:
            raise ServiceError(f"method {method!r} is not one of {', '.join(METHODS)}")
        if top < 1:
            raise ServiceError(f"top must be at least 1, not {top}")
        with self.sparql.lock:
            matchmaker = self.matchmakers.get(method)
            result = _call(lambda: matchmaker.rank(requirement, explain=top))
        return result.to_dict(top)

    def plan(self, args: dict[str, Any]) -> dict[str, Any]:
        """The task composed as ``cbrs plan`` composes it: in a home of two or more mobile bases, the plan of
        the base a run would choose (``actions.base_choice.choose_in_map``), and ``base`` says which and why.
        The options are checked as a run's are (``check_choice``, ``check_near_misses``: the same words)."""
        from cbrs.actions.base_choice import BaseTies, choose_in_map  # the planner loads with the first plan
        from cbrs.actions.composer import Objective, store_plan
        from cbrs.task_names import task_iri

        task = _field(args, "task", str)
        objective = _field(args, "objective", str, "") or Objective.SIMILARITY.value
        ties = _field(args, "base_ties", str, "") or BaseTies.NEAREST.value
        near = args.get("near_misses")
        near = near if _given(near, _UNSET["near_misses"]) else None
        _call(lambda: (check_choice("objective", objective, Objective), check_choice("base_ties", ties, BaseTies)))
        near_misses = _call(lambda: check_near_misses(near))
        with self.sparql.lock:
            composer = self.composers.get(Objective(objective), near_misses)
            iri = _call(lambda: task_iri(self.sparql.kb, task))
            result, chosen = _call(lambda: choose_in_map(composer, iri, composer.compose(iri), BaseTies(ties)))
            recorded = result.plan is not None and not self.sparql.config.read_only and self.may_write()
            if result.plan is not None and recorded:
                store_plan(self.sparql.kb, result.plan)
        found = {**result.to_dict(), "recorded": recorded}
        if chosen is not None:  # a home of one mobile base, or none: the answer as before
            found["base"] = chosen.to_dict()
        return found

    def known_tasks(self, args: dict[str, Any]) -> dict[str, Any]:
        return {"tasks": _call(self.tasks.tasks)}

    def run_task(self, args: dict[str, Any]) -> dict[str, Any]:
        request = self._run_request(args)
        if _field(args, "wait", bool, True):
            run = _call(lambda: self.tasks.run(**request, timeout=self.wait_limit))
        else:
            run = _call(lambda: self.tasks.start(**request))
        return run.to_dict(with_events=False)

    def run_task_goal(self, goal: GoalHandle) -> GoalResult:
        """The /cbrs/run_task action: start the run, relay its steps as feedback, wait for its end.

        A cancel asks the run to stop after the step under way (at once during a remote call, abandoned:
        docs/execution.md, "A Stop during a remote call"); a queued run it takes out of the queue. The wait has
        no deadline of its own: a run always ends (the executor's tick bound), a queued one ends when the server
        stops (``TaskRunner.close``), and a server stopping cancels the goal.
        """
        _check_fields("/cbrs/run_task", _RUN, goal.args)
        request = self._run_request(goal.args)
        with self.sparql.lock:
            realises = {ad.iri: ad.realizes_action for ad in self.sparql.kb.advertisements(include_unavailable=True)}
        feed = StepFeed(goal, realises)
        unsubscribe = self.tasks.subscribe(feed)
        try:
            run = _call(lambda: self.tasks.start(**request))
            feed.follow(run)

            def cancel() -> None:
                self.tasks.cancel(run.id)  # the run stops after the step under way, or abandons its remote call

            goal.on_cancel(cancel)
            run.done.wait()
        finally:
            unsubscribe()
        return GoalResult(GOAL_STATUS.get(run.status, GoalStatus.ABORTED), run.to_dict(with_events=False))

    def _run_request(self, args: dict[str, Any]) -> dict[str, Any]:
        """A run's task, seed, failing components, fault rate, repeat bound and composition options, checked,
        from a client that may write: the keywords of ``TaskRunner.start``. The options go to it as given
        (but those :data:`_UNSET`), so a bad one is refused with the words ``POST /tasks`` refuses it with."""
        task = _field(args, "task", str)
        seed = _field(args, "seed", int, 0)
        faults = _field(args, "fail", list, [])
        repeats = _field(args, "repeat_failures", int, 1)
        rate = args.get("fault_rate", 0.0)
        if not all(isinstance(f, str) for f in faults):
            raise ServiceError("fail must be a list of component IRIs (strings)")
        if isinstance(rate, bool) or not isinstance(rate, (int, float)):
            raise ServiceError(f"field 'fault_rate' must be a number in [0, 1], not {type(rate).__name__}")
        if not self.may_write() and not self.sparql.config.read_only:  # a read-only server says so itself
            caller = current_caller()
            if caller is not None and caller.token_refused:
                raise ServiceError(f"a task run moves the robot and writes the store: {TOKEN_REFUSED}")
            raise ServiceError(
                "a task run moves the robot and writes the store: send the update token first "
                '({"op": "auth", "mac": "<token>"}), or start it from this server\'s tasks page'
            )
        options = {name: args[name] for name, unset in _UNSET.items() if name in args and _given(args[name], unset)}
        found = {"task": task, "seed": seed, "faults": faults, "fault_rate": float(rate), "repeat_failures": repeats}
        return {**found, **options}

    def task_status(self, args: dict[str, Any]) -> dict[str, Any]:
        run_id = _field(args, "run", str)
        return _call(lambda: self.tasks.get(run_id)).to_dict()


class StepFeed:
    """A task listener that turns one run's step events into its goal's feedback: one message per step
    that ends, naming the run and its task (``iri``, ``shown``) as the run's result names them, so a
    client that follows several runs need not keep its goals' names. Events that come before the run is
    known are held, then relayed in order."""

    def __init__(self, goal: GoalHandle, realises: dict[str, str | None]) -> None:
        self.goal = goal
        self.realises = realises  # component IRI -> the action class it realises
        self._lock = threading.Lock()
        self._run: str | None = None
        self._names: dict[str, str] = {}  # the run's iri and shown, as its record (TaskRun.to_dict) has them
        self._early: list[dict[str, Any]] = []
        self._plan = 1
        self._queued = False

    def __call__(self, topic: str, message: dict[str, Any]) -> None:
        if topic != "/cbrs/task_progress" and not (topic == RUN_TOPIC and message.get("event") == "run_started"):
            return
        with self._lock:  # held while relaying, so the held events go first
            if self._run is None:
                self._early.append(message)
            else:
                self._relay(message)

    def follow(self, run: TaskRun) -> None:
        """The run is known: relay what came before and follow it from now on. A queued run is said so
        first (``status`` queued, its place in line as ``reason``); its start is said when it comes."""
        with self._lock:
            self._run = run.id
            self._names = {"iri": run.iri, "shown": run.shown or run.task}
            self._queued = run.queued is not None
            position = run.position
            if self._queued:
                place = in_line(position) if position is not None else "its turn has come"
                self.goal.publish_feedback(
                    {
                        "run": run.id,
                        **self._names,
                        "status": "queued",
                        "reason": f"queued behind the run going: {place}",
                    }
                )
            early, self._early = self._early, []
            for message in early:
                self._relay(message)

    def _relay(self, message: dict[str, Any]) -> None:
        if message.get("run") != self._run:
            return
        event = message.get("event")
        if event == "run_started":
            if self._queued:  # a queued run's turn came: said once, before its steps
                self.goal.publish_feedback({"run": self._run, **self._names, "status": "running", "reason": ""})
        elif event == "replanning":
            self._plan = int(message.get("plan", self._plan + 1))
        elif event in ("step_succeeded", "step_failed"):
            component = message.get("component")
            self.goal.publish_feedback(
                {
                    "run": self._run,
                    **self._names,
                    "plan": self._plan,
                    "step": message.get("step"),
                    "action": self.realises.get(component) if isinstance(component, str) else None,
                    "component": component,
                    "status": "succeeded" if event == "step_succeeded" else "failed",
                    "reason": message.get("reason", ""),
                    "failover": message.get("failover"),
                }
            )


class Composers:
    """Composers kept between /cbrs/plan calls, one per objective and count of near misses, sharing the
    taxonomy index (with the matchmakers, when given them), the action library and the advertisements
    (building them is most of a call's time).

    They are made again when the store changes: an update through the endpoint or a component
    registered or leaving (``SparqlService.generation``), a component whose lease lapsed (the set of
    unavailable components), and on a remote store, other processes' writes (the sizes of the
    ontology and services graphs). Call ``get`` and compose with the knowledge-base lock held: a
    composer is not safe for two compositions at once.
    """

    def __init__(self, sparql: SparqlService, matchmakers: Matchmakers | None = None) -> None:
        self.sparql = sparql
        self.matchmakers = matchmakers  # whose taxonomy index the composers take: one per store version
        self._version: object = None
        self._built: dict[tuple[Objective, int], Composer] = {}

    def get(self, objective: Objective, near_misses: int | None = None) -> Composer:
        """The composer of ``objective`` naming ``near_misses`` per unmet need (None: ``ComposeConfig``'s)."""
        from cbrs.actions.composer import ComposeConfig, Composer

        kb = self.sparql.kb
        version: tuple[object, ...] = (self.sparql.generation, frozenset(kb.liveness.unavailable()))
        if is_remote(kb.store.location):
            version += (kb.store.count(GraphName.ONTOLOGY), kb.store.count(GraphName.SERVICES))
        if version != self._version:
            self._version, self._built = version, {}
        config = ComposeConfig(objective=objective)
        config = config if near_misses is None else replace(config, near_misses=near_misses)
        key = (objective, config.near_misses)
        composer = self._built.get(key)
        if composer is None:
            shared = next(iter(self._built.values()), None)
            matchmakers = self.matchmakers
            index = shared.index if shared is not None else matchmakers.index() if matchmakers is not None else None
            composer = Composer(
                kb,
                config,
                index=index,
                actions=shared.actions if shared is not None else None,
                advertisements=shared.advertisements if shared is not None else None,
            )
            self._built[key] = composer
        return composer


def attach(bridge: Bridge, services: KnowledgeServices) -> Callable[[], None]:
    """Offer ``services`` on ``bridge`` and relay task events to its topics; returns the detach call."""
    services.wait_limit = max(0.5, min(services.wait_limit, bridge.call_timeout - 2.0))
    bridge.interfaces.load(INTERFACES, "cbrs")
    for name, (kind, handler) in services.handlers().items():
        bridge.add_service(name, kind, handler)
    for topic, kind in TOPICS.items():
        bridge.add_topic(topic, kind)
    for action, kind in ACTIONS.items():
        bridge.add_action(action, kind, services.run_task_goal)

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


def _given(value: object, unset: tuple[object, ...]) -> bool:
    """Whether ``value`` is given, not one of the ``unset`` values (of the same type: -1.0 or True is given,
    and refused as such)."""
    return not any(value is u or (type(value) is type(u) and value == u) for u in unset)


def _known_fields(service: str, fields: tuple[str, ...], handler: Handler) -> Handler:
    def checked(args: dict[str, Any]) -> dict[str, Any]:
        _check_fields(service, fields, args)
        return handler(args)

    return checked


def _check_fields(service: str, fields: tuple[str, ...], args: dict[str, Any]) -> None:
    unknown = [name for name in args if name not in fields]
    if not unknown:
        return
    close = difflib.get_close_matches(unknown[0], fields, n=1)
    meant = f" (did you mean {close[0]!r}?)" if close else ""
    takes = f"it takes {', '.join(fields)}" if fields else "it takes no field"
    raise ServiceError(f"{service} has no field {unknown[0]!r}{meant}: {takes}")


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
