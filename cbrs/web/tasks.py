"""The tasks page: start any task the store can express in the simulated home and follow it live.

Live updates travel as server-sent events (``/tasks/events``) and the ceiling camera as an MJPEG
stream (``/camera.mjpg``). Each open stream holds one of waitress's threads, so streams are counted
(:class:`cbrs.web.context.StreamSlots`: a few in all, four per client address; one more is refused
with 503) and end by themselves: after ``CBRS_STREAM_SECONDS`` at most, or ``CBRS_STREAM_IDLE_SECONDS``
without news, or as soon as a write finds the client gone (a heartbeat or a repeated frame every few
seconds makes sure one is tried). The browser's EventSource reconnects by itself; the page restarts
the camera stream when a run starts.
"""

from __future__ import annotations

import difflib
import functools
import hmac
import json
import queue
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any, Generic, TypeVar

from flask import Blueprint, Response, current_app, request, url_for
from flask.sansio.blueprints import BlueprintSetupState
from werkzeug.exceptions import BadRequest, Forbidden, NotFound, ServiceUnavailable

from cbrs.actions.errors import UnknownTaskError
from cbrs.kb.namespaces import PREFIXES, written
from cbrs.kb.owls import local_name
from cbrs.tasks import (
    CameraFrame,
    RunOptionError,
    TaskBusyError,
    TaskRun,
    TaskRunner,
    TasksDisabledError,
    UnknownComponentError,
    in_line,
    preconditions_line,
)
from cbrs.web import context, services
from cbrs.web.links import expand_name, short, shown_task, task_name
from cbrs.web.pages import FormError, Page, page, wants_json
from cbrs.web.prefixes import derived, namespace

blueprint = Blueprint("tasks", __name__)

DEFAULTS = {
    "CBRS_STREAM_SECONDS": 600.0,  # the longest a stream lives; EventSource reconnects after it ends
    "CBRS_STREAM_IDLE_SECONDS": 120.0,  # a stream with no event (no new frame) this long ends
    "CBRS_HEARTBEAT_SECONDS": 5.0,  # an SSE comment this often, so a gone client is noticed
    "CBRS_CAMERA_REPEAT_SECONDS": 2.0,  # the last frame again this often, so the browser keeps showing it
    "CBRS_FIRST_FRAME_SECONDS": 3.0,  # the longest a camera watcher joining mid-run waits for the run's frame
    "CBRS_LIVE_PREFIXES": 50,  # at most this many derived prefixes go to tasks.js (the components' namespaces)
}
SLICE = 0.5  # seconds a stream waits at most before it looks whether the server is closing
QUEUE_SIZE = 1000  # events a slow client may fall behind by before its stream ends (a run sends ~150)
BOUNDARY = "frame"
STEP_EVENTS = ("step_started", "step_succeeded", "step_failed")
MAX_STARTERS = 256  # runs whose starting address is kept, for who may stop them (the runner keeps fewer runs)
_STARTERS_LOCK = threading.Lock()  # held while the table of who started which run is written


@blueprint.record_once
def _defaults(state: BlueprintSetupState) -> None:
    for name, value in DEFAULTS.items():
        state.app.config.setdefault(name, value)


@page(blueprint, "/tasks", negotiate=True, methods=["GET", "POST"])
def tasks() -> Page:
    """The tasks to start, the run going now (or the last one), the camera and the recent runs.

    A POST starts a run (202, its ``Location`` the run's page, or its JSON for a JSON answer; a browser's form
    is sent on to the run's page, 303: :func:`_from_a_browser`); while one is going it waits in the runner's
    queue when there is room (202 too, ``queued`` with its ``position``), else it is refused with 409 and says
    which run goes (and that the queue is full, with a queue). A program gets JSON here as at ``/tasks.json`` when
    it prefers it (:func:`cbrs.web.pages.prefers_json`).
    """
    form = _form()
    shown = Page("tasks.html", "Tasks", {"mode": "tasks", **_overview(form)})
    _for_script(shown)
    if request.method != "POST":
        _check_asked(form, shown)
        return shown
    _may_act()
    try:
        started = context.tasks().start(**_checked(form, shown))
    except UnknownTaskError as error:
        raise FormError({"task": str(error)}, page=shown) from None
    except UnknownComponentError as error:
        raise FormError({"fail": str(error)}, page=shown) from None
    except RunOptionError as error:
        raise FormError({error.field: str(error)}, page=shown) from None
    except TaskBusyError as error:
        shown.status = 409
        shown.data.update(error="busy", message=str(error), running=error.running)
        return shown
    _starters(started.id)
    shown.status = 303 if _from_a_browser() else 202  # Post/Redirect/Get: a reload re-sent the form, a 409 mid-run
    shown.headers["Location"] = url_for("tasks.run_json" if wants_json() else "tasks.run", run_id=started.id)
    queued = started.status == "queued"
    shown.title = f"Tasks: {started.id} {'queued' if queued else 'started'}"
    said = f"{started.id} {'queued' if queued else 'started'}: {shown_task(started.task, started.iri)}"
    if queued:
        said += f", {_in_line(started)}; it starts when the runs before it have ended"
    shown.data.update(_overview(form), started=_started(started), message=said)
    return shown


@page(blueprint, "/tasks/<run_id>", negotiate=True)
def run(run_id: str) -> Page:
    """One run: its steps, every event it published, and its result (the plan and execution report)."""
    found = context.tasks().get(run_id)  # an unknown run: 404
    data = {"mode": "run", "run": _detail(found), **_live()}
    if found.reason:  # taken out of the queue (Stop, the server stopping): said in place of the stop under way
        data["message"] = f"{found.id} ended {found.status} without starting: {found.reason}"
    elif found.cancel_requested.is_set():  # what Stop's 303 led here to say (the run may have ended meanwhile)
        data["message"] = _stopping(found) + (f"; it ended {found.status}" if found.done.is_set() else "")
    return _for_script(Page("tasks.html", f"Run {found.id}: {data['run']['shown']}, {found.status}", data))


@page(blueprint, "/tasks/<run_id>/cancel", negotiate=True, methods=["POST"])
def cancel(run_id: str) -> Page:
    """Ask a run to stop after the step under way, or at once while it waits on a remote component's call, which
    it abandons (202); the same people who may start a run may stop it.

    A browser's form is sent on to the run's page (303, as Start's is: :func:`_from_a_browser`): it stayed at
    ``/cancel``, and a reload sent the Stop again and got the 409 below. A run that has already ended is left
    as it is and said so (409), as the bridge's cancel does. A queued run is taken out of the queue (202; it
    ends ``cancelled`` without starting), by the same people.
    """
    _may_act("stopped")
    found = context.tasks().get(run_id)  # an unknown run: 404
    _may_stop(found)
    data = {"mode": "run", **_live()}
    if found.done.is_set():
        data.update(run=_detail(found), error="ended", message=f"{found.id} has already ended: {found.status}")
        shown = Page("tasks.html", f"Run {found.id}: {shown_task(found.task, found.iri)}, {found.status}", data)
        shown.status = 409
        return _for_script(shown)
    was_queued = found.status == "queued"
    context.tasks().cancel(run_id)
    said = _stopping(found) if not found.reason else f"{found.id} {found.reason}; it ends {found.status}"
    data.update(run=_detail(found), message=said)
    state = "taken out of the queue" if was_queued and found.reason else "stopping"
    shown = Page("tasks.html", f"Run {found.id}: {shown_task(found.task, found.iri)}, {state}", data)
    shown.status = 202
    if _from_a_browser():  # Post/Redirect/Get
        shown.status = 303
        shown.headers["Location"] = url_for("tasks.run", run_id=found.id)
    return _for_script(shown)


def _in_line(found: TaskRun) -> str:
    return in_line(found.position or 1)


def _starters(started: str | None = None) -> dict[str, str | None]:
    """Which address started each run from a page (``POST /tasks``), the last ``MAX_STARTERS``; with
    ``started``, this request's address is recorded for that run."""
    found: dict[str, str | None] = current_app.extensions.setdefault("cbrs.run_starters", {})
    if started is not None:
        # two Starts at once, the table full: unlocked, one trimming the oldest while the other added could
        # fail (the dict changed size during iteration) or both delete the same key (KeyError), a 500 for a
        # run that had started
        with _STARTERS_LOCK:
            found[started] = request.remote_addr
            while len(found) > MAX_STARTERS:
                del found[next(iter(found))]
    return found


def _may_stop(found: TaskRun) -> None:
    """A page stops only a run its own computer started (its address); another run needs the update token
    (``Authorization: Bearer``, or the Stop form's token field). In a class on one server every tasks page
    showed Stop for the run going, and any student's click stopped the teacher's run, or another's."""
    starter = _starters().get(found.id)
    if (starter is not None and starter == request.remote_addr) or _has_token() or _token_typed():
        return
    where = "another computer" if starter is not None else "a program (over the bridge or with the token)"
    raise Forbidden(
        f"{found.id} was started from {where}: a page stops only the runs its own computer started; whoever "
        "started cbrs serve may stop it, with the update token typed beside Stop this run"
    )


def _token_typed() -> bool:
    """Whether the form's ``token`` field holds the server's update token (a page's Stop form)."""
    expected = context.sparql().config.update_token
    typed = request.form.get("token", "").strip() if request.method == "POST" else ""
    return bool(expected and typed) and hmac.compare_digest(typed.encode("utf-8"), str(expected).encode("utf-8"))


def _stopping(found: TaskRun) -> str:
    at_once = "a remote component's call under way is abandoned at once"
    return f"{found.id}: asked to stop after the step under way ({at_once})"


def _from_a_browser() -> bool:
    """Whether a page's answer goes to a browser's form, which names ``text/html`` in its ``Accept``: it is
    sent on to the run's page (303), so that a reload or Back does not send the form again (a second Start,
    refused with 409 while the run goes). A program's form post (curl's ``*/*``) keeps the 202 and the page."""
    return not wants_json() and any(value == "text/html" for value, _ in request.accept_mimetypes)


def _for_script(shown: Page) -> Page:
    if not wants_json():
        shown.data["prefixes"] = {**_component_prefixes(), **PREFIXES}
    return shown


def _component_prefixes() -> dict[str, str]:
    """The prefixes derived for the namespaces of the advertisements (a lab's plug: ``lab10:``), for tasks.js
    to name live events' IRIs as the page names them; none when they are more than
    ``CBRS_LIVE_PREFIXES``: OWLS-TC's 1,144 made the page 145 KB bigger, and its services run no task."""
    by_prefix = derived()
    if not by_prefix:
        return {}
    by_ns = {ns: prefix for prefix, ns in by_prefix.items()}
    rows = services.advertisement_rows(context.kb())
    used = {by_ns[ns] for ns in (namespace(row["service"]) for row in rows) if ns in by_ns}
    return (
        {prefix: by_prefix[prefix] for prefix in sorted(used)}
        if len(used) <= current_app.config["CBRS_LIVE_PREFIXES"]
        else {}
    )


def _check_asked(form: dict[str, Any], shown: Page) -> None:
    """A task the URL names (``/tasks?task=``, a link or a bookmark) chosen as the list spells it
    (``req:FetchMyPen`` chooses FetchMyPen); one the store has not, a field error with its did-you-mean
    (400), as the plans page says it. It was added to the list as typed and refused only at Start."""
    asked = form["task"] if "task" in request.args else ""
    offered = choices()["tasks"]
    if not asked or asked in offered:
        return
    from cbrs.task_names import task_iri

    try:
        with context.lock():
            iri = task_iri(context.kb(), task_name(asked))
    except UnknownTaskError as error:
        raise FormError({"task": str(error)}, page=shown) from None
    listed = _typed(iri, offered)
    if listed is not None:
        shown.data["form"] = {**shown.data["form"], "task": listed}


#: With the composition options cbrs run takes (--objective, --base-ties, --near-misses; TaskRunner.start checks them)
RUN_FIELDS = ("task", "seed", "fail", "fault_rate", "repeat_failures", "objective", "base_ties", "near_misses")


def _form() -> dict[str, Any]:
    body = _json_body() if request.is_json and request.method == "POST" else None
    if body is not None:
        fail = body.get("fail", [])
        return {
            "task": str(body.get("task", "")),
            "seed": str(body.get("seed", 0)),
            "fail": [str(f) for f in (fail if isinstance(fail, list) else [fail])],
            "fault_rate": str(body.get("fault_rate", 0)),
            "repeat_failures": str(body.get("repeat_failures", 1)),
            "objective": str(body.get("objective", "similarity")),
            "base_ties": str(body.get("base_ties", "nearest")),
            "near_misses": "" if body.get("near_misses") is None else str(body["near_misses"]),
        }
    values = request.form if request.method == "POST" else request.args
    return {
        "task": values.get("task", "").strip(),
        "seed": values.get("seed", "0").strip(),
        "fail": [f.strip() for f in values.getlist("fail") if f.strip()],
        "fault_rate": values.get("fault_rate", "0").strip(),
        "repeat_failures": values.get("repeat_failures", "1").strip(),
        "objective": values.get("objective", "").strip() or "similarity",
        "base_ties": values.get("base_ties", "").strip() or "nearest",
        "near_misses": values.get("near_misses", "").strip(),
    }


def _json_body() -> dict[str, Any]:
    """A run asked for in JSON: an object of ``RUN_FIELDS``. Broken JSON, another value, or a field the run
    does not take is refused, naming it: they were read as an empty form ("choose a task"), and a
    misspelt field ("sed") was dropped, the run started with its default."""
    body = request.get_json(silent=True)
    if not isinstance(body, dict):
        found = "not JSON" if body is None else f"a JSON {type(body).__name__}"
        raise BadRequest(f'the body is {found}: send an object of the run\'s fields, e.g. {{"task": "FetchMyPen"}}')
    unknown = [name for name in body if name not in RUN_FIELDS]
    if unknown:
        near = difflib.get_close_matches(unknown[0], RUN_FIELDS, n=1)
        meant = f"did you mean {near[0]!r}? " if near else ""
        raise FormError({unknown[0]: f"no such field; {meant}a run takes {', '.join(RUN_FIELDS)}"})
    return body


def _as_listed(task: str) -> str:
    """A task named with a prefix the pages derived (``lab10:SwitchOnTheReadingLamp``, as the New task page's
    link names it) as the list spells it, which the runner takes; any other name as typed."""
    iri = task_name(task)
    return task if iri == task else (_typed(iri, choices()["tasks"]) or iri)


def _checked(form: dict[str, Any], shown: Page) -> dict[str, Any]:
    """The form's fields as ``TaskRunner.start`` takes them; a FormError naming each bad one. The task
    name itself is checked by the runner, against the store (with a did-you-mean)."""
    errors = {}
    if not form["task"]:
        errors["task"] = "choose a task"
    seed = 0
    try:
        seed = int(form["seed"] or "0")
    except ValueError:
        errors["seed"] = f"{form['seed']!r} is not a whole number"
    faults = []
    for name in form["fail"]:
        try:
            faults.append(expand_name(name))
        except ValueError as error:
            errors["fail"] = str(error)
    fault_rate = 0.0
    try:
        fault_rate = float(form["fault_rate"] or "0")
    except ValueError:
        errors["fault_rate"] = f"{form['fault_rate']!r} is not a number"
    if not 0.0 <= fault_rate <= 1.0:  # also refuses nan
        errors["fault_rate"] = f"{form['fault_rate']!r} is not a probability between 0 and 1"
    repeats = 1
    try:
        repeats = int(form["repeat_failures"] or "1")
    except ValueError:
        errors["repeat_failures"] = f"{form['repeat_failures']!r} is not a whole number"
    if repeats < 0:
        errors["repeat_failures"] = f"{form['repeat_failures']!r} is negative: a number of repeats is 0 or more"
    near_misses = None  # ComposeConfig's default; the options' values are checked by TaskRunner.start
    try:
        near_misses = int(form["near_misses"]) if form["near_misses"] else None
    except ValueError:
        errors["near_misses"] = f"{form['near_misses']!r} is not a whole number"
    if errors:
        raise FormError(errors, page=shown)
    return {
        "task": _as_listed(form["task"]),
        "seed": seed,
        "faults": faults,
        "fault_rate": fault_rate,
        "repeat_failures": repeats,
        "objective": form["objective"],
        "base_ties": form["base_ties"],
        "near_misses": near_misses,
    }


def _may_act(verb: str = "started") -> None:
    """Starting (or stopping) a run moves a (simulated) robot and writes the store: from this server's own
    pages (their ``Origin``), or with the update token. Behind ``cbrs serve`` the pages' origins are those of the
    address it binds, never read from the request; a request with no ``Origin`` (not a browser) needs
    the token."""
    if from_own_page(verb):
        return
    if not _has_token():
        config = context.sparql().config
        if config.read_only:  # no page and no token would help
            raise TasksDisabledError()
        if config.update_token is None:  # no token to send: say the one way there is
            raise Forbidden(
                f"a task run moves the robot: this server has no update token, so a run may be {verb} only from "
                "its own tasks page (or start cbrs serve with CBRS_UPDATE_TOKEN and send Authorization: Bearer <token>)"
            )
        given = request.headers.get("Authorization", "").strip()
        if given:  # a token that is not the server's read the same as none: a person looked for a missing header
            scheme = given.partition(" ")[0]
            what = (
                "the bearer token sent is not this server's update token"
                if scheme.lower() == "bearer"
                else f"the Authorization header gives {scheme!r}, not a bearer token"
            )
            raise Forbidden(
                f"a task run moves the robot: {what}; send Authorization: Bearer <token> with the token "
                "cbrs serve was started with, or use this server's tasks page"
            )
        raise Forbidden(
            f"a task run moves the robot: it may be {verb} from this server's tasks page, or with the update token "
            "(Authorization: Bearer <token>)"
        )


def from_own_page(verb: str, what: str = "a task") -> bool:
    """Whether the request comes from one of this server's own pages (its ``Origin`` one of the origins
    ``cbrs serve`` binds); Forbidden for another site's page, naming it and ``what`` is ``verb`` (a file
    loaded, not a task); False for a request with no ``Origin`` (a program, not a browser). An app not
    behind cbrs serve (a test client) knows only the page's own host, and takes a request with no
    ``Origin`` for its own."""
    origin = request.headers.get("Origin")
    own = current_app.extensions.get("cbrs.own_origins")
    foreign = f"{what} may be {verb} only from this server's own pages, not from {origin}"
    if own is None:
        if origin is not None and origin.rstrip("/") != request.host_url.rstrip("/"):
            raise Forbidden(foreign)
        return True
    if origin is not None:
        if origin.rstrip("/") not in own():
            raise Forbidden(foreign)
        return True
    return False


def _has_token() -> bool:
    expected = context.sparql().config.update_token
    scheme, _, given = request.headers.get("Authorization", "").partition(" ")
    if expected is None or scheme.lower() != "bearer" or not given.strip():
        return False
    return hmac.compare_digest(given.strip().encode("utf-8"), expected.encode("utf-8"))


def _overview(form: dict[str, Any]) -> dict[str, Any]:
    runner = context.tasks()
    active = runner.active()
    runs = runner.runs()
    latest = active or (runs[-1] if runs else None)
    offered = choices()
    if not form["task"]:
        form = {**form, "task": _first_choice(offered, latest)}
    return {
        "form": form,
        "options": run_options(),
        "tasks": offered["tasks"],
        "labels": offered["labels"],
        "shown_names": offered["shown"],
        "components": offered["components"],
        "active": _detail(latest) if latest is not None else None,
        "runs": [_summary(r) for r in reversed(runs)],
        "run_queue": runner.queue_size,
        "waiting": len(runner.waiting()),
        **_live(),
    }


@functools.cache
def run_options() -> dict[str, Any]:
    """What the start form offers for the composition options ``cbrs run`` takes: the objectives and the
    base ties by name, the CLI's default first, and ``ComposeConfig``'s number of near misses."""
    from cbrs.actions.base_choice import BaseTies  # the planner loads with the first use
    from cbrs.actions.composer import ComposeConfig, Objective

    defaults = ComposeConfig()
    return {
        "objectives": [defaults.objective.value, *(o.value for o in Objective if o is not defaults.objective)],
        "base_ties": [BaseTies.NEAREST.value, *(t.value for t in BaseTies if t is not BaseTies.NEAREST)],
        "near_misses": defaults.near_misses,
    }


def choices() -> dict[str, Any]:
    """What the start form offers, read once per store generation (on OWLS-TC the tasks and components
    took 0.3 and 0.6 s of every tasks page): the tasks as a person types them, the components a run may
    be told to fail, and the tasks of several steps (below), the first of which the form starts with."""

    def read() -> dict[str, Any]:
        from cbrs.actions.model import ActionLibrary  # the planner loads with the first use

        runner, kb = context.tasks(), context.kb()
        with context.lock():
            known = runner.tasks()
            actions = [action for action in ActionLibrary.from_kb(kb) if action.sub_actions]
            rows = kb.select("requirements")
        composite = {action.iri for action in actions}
        stated = sorted({row["requirement"].value for row in rows if "task" in row and row["task"].value in composite})
        several = sorted(name for name in (_typed(iri, known) for iri in stated) if name is not None)
        # each task's label beside its name, as the plans page shows them ("FetchMyPen · Fetch my pen")
        labelled = [(row["requirement"].value, row["label"].value) for row in rows if "label" in row]
        labelled += [(action.iri, action.label) for action in actions if action.label]
        labels = {name: label for name, label in ((_typed(iri, known), label) for iri, label in labelled) if name}
        listed = ((_typed(iri, known), iri) for iri in {row["requirement"].value for row in rows} | composite)
        shown = {name: shown_task(name, iri) for name, iri in listed if name is not None}
        return {
            "tasks": known,
            "labels": labels,
            "shown": {name: text for name, text in shown.items() if text != name},
            "components": [short(c) for c in runner.components()],
            "several": several,
        }

    return context.per_generation("task_choices", read)


def _typed(iri: str, known: list[str]) -> str | None:
    """How the list spells the task ``iri`` (``cbrs.task_names``: its bare name when that means it, else its
    prefixed name or ``<IRI>``); None when it is not listed."""
    for name in (written(iri), local_name(iri)):
        if name in known:
            return name
    return None


def _first_choice(offered: dict[str, Any], latest: TaskRun | None) -> str:
    """The task the form starts with, when the URL names none: the latest run's, so that a user trying a
    task again after a failure or a change finds it chosen; else the first by name of the requirements
    that ask for an action of several steps (``cbrs:forTask`` an action with sub-actions), a task that
    shows this page's steps, failovers and camera (FetchMyPen in the bundled store); else the first task."""
    if latest is not None:
        again = _typed(latest.iri, offered["tasks"]) if latest.iri else None
        if again is not None:
            return again
    return str(next(iter(offered["several"] or offered["tasks"]), ""))


def _live() -> dict[str, Any]:
    """Where the page follows runs: the event stream, and the camera with its latest frame's number."""
    camera = {
        "frame": context.tasks().frame_number,
        "stream": url_for("tasks.camera"),
        "still": url_for("tasks.snapshot"),
    }
    return {"event_stream": url_for("tasks.events"), "camera": camera}


def _summary(found: TaskRun) -> dict[str, Any]:
    data = found.to_dict(with_events=False)
    data.pop("result", None)
    data["faults"] = [short(f) for f in found.faults]
    data["url"] = url_for("tasks.run", run_id=found.id)
    data["shown"] = shown_task(found.task, found.iri)
    if found.status == "queued":
        data["in_line"] = _in_line(found)
    return data


def _started(found: TaskRun) -> dict[str, Any]:
    """A run just started: its ``url`` where this answer's ``Location`` points (the status JSON for a JSON
    answer, the page for the page), and its ``page`` for a person."""
    data = _summary(found)
    data["page"] = data["url"]
    if wants_json():
        data["url"] = url_for("tasks.run_json", run_id=found.id)
    return data


def _detail(found: TaskRun) -> dict[str, Any]:
    data = found.to_dict()
    data["url"] = url_for("tasks.run", run_id=found.id)
    data["shown"] = shown_task(found.task, found.iri)
    if found.status == "queued":
        data["in_line"] = _in_line(found)
    data["steps"] = steps(data["events"])
    data["unmet"] = unmet(data.get("result"))
    data["verdict"] = verdict(data)
    found_before = (data.get("result") or {}).get("preconditions", [])  # the task's own, before the first step
    line = preconditions_line(found_before, listed="the run's JSON lists each")
    data["preconditions_line"] = line[:1].upper() + line[1:]  # a sentence of the page's
    return data


def unmet(result: dict[str, Any] | None) -> list[str]:
    """What no component provides, each need with its remedy, when the run made no plan: the run page
    said only "Plan: unsolvable", and the reasons were in its JSON alone."""
    plan = (result or {}).get("plan") or {}
    return [str(need.get("text") or need.get("need")) for need in plan.get("unsatisfied", [])]


def verdict(run: dict[str, Any]) -> str | None:
    """How the run ended, in a line: the execution's status and reason, why no plan came of it, or the
    error; None while it runs."""
    result = run.get("result") or {}
    execution = result.get("execution")
    if execution:
        reason = f": {execution['reason']}" if execution.get("reason") else ""
        return f"{execution['status']}{reason}; {result.get('sim_seconds', 0.0)} s simulated"
    if run.get("error"):
        return str(run["error"])
    if run.get("reason"):  # it never started: taken out of the queue
        return f"{run.get('status')} without starting: {run['reason']}"
    plan = result.get("plan")
    if not plan or run.get("status") != "no-plan":
        return None
    needs = run.get("unmet") or []
    why = f": {needs[0]}" + (f" (and {len(needs) - 1} more, below)" if len(needs) > 1 else "") if needs else ""
    return f"no plan ({plan.get('status')}), nothing was simulated{why}"


def steps(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per plan step from a run's progress events: the components tried, in order, and the
    outcome; after a re-plan, the new plan's steps follow the old one's (``plan`` counts from 1)."""
    rows: dict[tuple[int, int], dict[str, Any]] = {}
    plan = 1
    for event in events:
        if event.get("topic", "/cbrs/task_progress") != "/cbrs/task_progress":
            continue
        if event.get("event") == "replanning":
            plan = int(event.get("plan", plan + 1))
            continue
        if event.get("event") not in STEP_EVENTS:
            continue
        row = rows.setdefault(
            (plan, event["step"]),
            {"plan": plan, "step": event["step"], "tried": [], "status": "started", "reasons": []},
        )
        if event["event"] == "step_started":
            if event["component"] not in row["tried"]:
                row["tried"].append(event["component"])
            row["status"] = "started"
        elif event["event"] == "step_succeeded":
            row["status"] = "succeeded"
        else:
            row["status"] = "failed"
            row["reasons"].append(event.get("reason", ""))
            row["failover"] = event.get("failover")
    for row in rows.values():
        row["failed_over"] = len(row["tried"]) > 1 or bool(row.get("failover"))
    return [rows[k] for k in sorted(rows)]


# -- live updates ----------------------------------------------------------------------------------


T = TypeVar("T")


class _Held(Generic[T]):
    """A response body that gives its stream slot back (and whatever else it holds: a camera watcher) when
    the server closes it, started or not (a generator closed before it starts runs no ``finally``)."""

    def __init__(self, body: Iterator[T], *releases: Callable[[], None]) -> None:
        self._body = body
        self._releases = releases

    def __iter__(self) -> Iterator[T]:
        return self._body

    def close(self) -> None:
        try:
            close = getattr(self._body, "close", None)
            if close is not None:
                close()
        finally:
            for release in self._releases:
                release()


def _held(body: Iterator[T], *also: Callable[[], None]) -> Iterable[T]:
    """``body`` holding a stream slot of the client's, and ``also`` released with it."""
    return _Held(body, context.streams().take(request.remote_addr or "unknown"), *also)


@blueprint.get("/tasks/events")
def events() -> Response:
    """Every task runner event as it happens, and the camera's frame numbers, as server-sent events."""
    runner = context.tasks()
    life, idle, closing = _stream_bounds()
    beat = float(current_app.config["CBRS_HEARTBEAT_SECONDS"])

    def stream() -> Iterator[str]:
        inbox: queue.Queue[dict[str, Any]] = queue.Queue(QUEUE_SIZE)
        overflow: list[bool] = []

        def put(message: dict[str, Any]) -> None:
            try:
                inbox.put_nowait(message)
            except queue.Full:
                overflow.append(True)

        def on_frame(frame: CameraFrame) -> None:
            put({"topic": "/cbrs/camera", "event": "frame", "frame": frame.number, "run": frame.run})

        # Subscribed here, not before: a generator closed before it starts runs no finally.
        unsubscribe = [
            runner.subscribe(lambda topic, message: put({"topic": topic, **message})),
            runner.on_frame(on_frame),
        ]
        try:
            active = runner.active()
            yield "retry: 3000\n\n"
            yield _sse({"event": "hello", "active": active.id if active else None, "frame": runner.frame_number})
            started = last = beaten = time.monotonic()
            reason = "idle"
            while True:
                now = time.monotonic()
                if now - started >= life:
                    reason = "life"
                    break
                if now - last >= idle:
                    break
                try:
                    message = inbox.get(timeout=max(0.01, min(SLICE, life - (now - started), idle - (now - last))))
                except queue.Empty:
                    if closing.is_set():
                        reason = "closing"
                        break
                    if time.monotonic() - beaten >= beat:
                        beaten = time.monotonic()
                        yield ": heartbeat\n\n"
                    continue
                if overflow:
                    reason = "overflow"
                    break
                last = time.monotonic()
                yield _sse(message)
            yield "event: end\n" + _sse({"event": "end", "reason": reason})
        finally:
            for call in unsubscribe:
                call()

    return Response(_held(stream()), mimetype="text/event-stream", headers=_no_buffering())


@blueprint.get("/camera.mjpg")
def camera() -> Response:
    """The ceiling camera as ``multipart/x-mixed-replace``: the frame now, each new one, the last again every ~2 s.

    The stream is a watcher of the camera (``TaskRunner.watch``): a run renders frames only while one is open,
    and one opened mid-run starts with a frame the run renders for it."""
    runner = context.tasks()
    life, idle, closing = _stream_bounds()
    repeat = float(current_app.config["CBRS_CAMERA_REPEAT_SECONDS"])

    def stream(frame: CameraFrame) -> Iterator[bytes]:
        started = last = sent = time.monotonic()
        # twice: a browser shows a part once the next one begins, so the picture (and the page's load
        # event) waited for the repeat CBRS_CAMERA_REPEAT_SECONDS later
        yield _part(frame)
        yield _part(frame)
        while True:
            now = time.monotonic()
            if now - started >= life or now - last >= idle or closing.is_set():
                return
            newer = runner.wait_frame(frame.number, max(0.01, min(SLICE, life - (now - started))))
            if newer is not None:
                frame, last = newer, time.monotonic()
            elif time.monotonic() - sent < repeat:
                continue
            sent = time.monotonic()
            yield _part(frame)

    release = runner.watch()
    try:
        first = _current_frame(runner)
        if first is None:
            raise ServiceUnavailable(_NO_FRAME)
        body = _held(stream(first), release)
    except BaseException:
        release()
        raise
    mimetype = f"multipart/x-mixed-replace; boundary={BOUNDARY}"
    return Response(body, headers={**_no_buffering(), "Content-Type": mimetype})


@blueprint.get("/camera.jpg")
def snapshot() -> Response:
    """The ceiling camera's view now, once (its number in ``X-Frame``): mid-run, one the run renders for it.

    ``?frame=N``: the latest frame, at once, when it is numbered N or more (the tasks page asks so for a
    frame the events or its checks announced, when the server had no stream slot left for its camera:
    twenty such pages asking the run for a frame each would hold twenty request threads and renders)."""
    runner = context.tasks()
    wanted = request.args.get("frame", type=int)
    latest = runner.frame() if wanted is not None and runner.camera is not None else None
    frame = latest if latest is not None and wanted is not None and latest.number >= wanted else None
    frame = frame or _current_frame(runner)
    if frame is None:
        raise NotFound(_NO_FRAME)
    return Response(
        frame.jpeg, mimetype="image/jpeg", headers={"Cache-Control": "no-store", "X-Frame": str(frame.number)}
    )


_NO_FRAME = "this server takes no camera frames"


def _current_frame(runner: TaskRunner) -> CameraFrame | None:
    """The frame a watcher starts with (``TaskRunner.current_frame``, waiting ``CBRS_FIRST_FRAME_SECONDS`` at
    most for a run to render it); None when there is none (no camera, no simulation, a run that rendered none
    in time)."""
    if runner.camera is None:
        return None
    return runner.current_frame(float(current_app.config["CBRS_FIRST_FRAME_SECONDS"]))


def _stream_bounds() -> tuple[float, float, threading.Event]:
    """How long a stream may live, how long it may go without news, and the server's closing signal."""
    config = current_app.config
    return float(config["CBRS_STREAM_SECONDS"]), float(config["CBRS_STREAM_IDLE_SECONDS"]), context.closing()


def _sse(message: dict[str, Any]) -> str:
    return f"data: {json.dumps(message, separators=(',', ':'))}\n\n"


def _part(frame: CameraFrame) -> bytes:
    head = (
        f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(frame.jpeg)}\r\n"
        f"X-Frame: {frame.number}\r\n\r\n"
    )
    return head.encode("ascii") + frame.jpeg + b"\r\n"


def _no_buffering() -> dict[str, str]:
    return {"Cache-Control": "no-store", "X-Accel-Buffering": "no"}
