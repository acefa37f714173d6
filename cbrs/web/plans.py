"""The plans page: compose a task into a plan of service invocations, as ``cbrs plan`` does, and draw
its service resource graph."""

from __future__ import annotations

import functools
import importlib
import re
import tempfile
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from flask import Blueprint, Response, request, url_for
from markupsafe import Markup

from cbrs.actions.shown_names import file_qualifier, shown_names, two_lines
from cbrs.extras import installed, require
from cbrs.iri_tail import tail_parts
from cbrs.kb.namespaces import expand, shorten
from cbrs.web import context, diagram
from cbrs.web.links import display_text, short, short_text, shown_task, task_name
from cbrs.web.pages import FormError, Page, page, wants_json

if TYPE_CHECKING:  # the planner (and networkx) load with the first plan asked for, not at start-up
    from cbrs.actions.base_choice import BaseChoice
    from cbrs.actions.composer import Composer, CompositionResult

blueprint = Blueprint("plans", __name__)


def _objectives() -> list[str]:
    from cbrs.actions.composer import Objective

    return [o.value for o in Objective]


def default_objective() -> str:
    from cbrs.actions.composer import Objective

    return Objective.SIMILARITY.value


@page(blueprint, "/plans")
def plans() -> Page:
    task = request.args.get("task", "").strip()
    objective = request.args.get("objective", "").strip() or default_objective()
    options = task_options()
    data: dict[str, Any] = {"task": task, "objective": objective, "objectives": _objectives(), "tasks": options}
    data["selected"] = _selected(task, options)
    shown = Page("plans.html", "Plans", data)
    if "task" not in request.args:
        if not wants_json():
            _load_drawing_library()  # while the user chooses a task
        return shown
    with context.lock():  # a GET stays safe: the plan is shown, not recorded (cbrs plan and /cbrs/plan record)
        composed = _composed(task, objective, shown)
    result = composed.result
    shown.title = f"Plan for {_shown_task(task, data['selected'])}"  # not "Plan for FetchMyPn" over the error
    data["composition"] = _composition(result)
    if composed.base is not None:  # a home of several mobile bases: the one the plan works, and why
        data["base"] = composed.base.to_dict()
    if not wants_json():  # markup, so not in the twin, which has the same steps as lists
        data["flow"] = _flow(data["composition"])
        _load_drawing_library()  # the page asks for the drawing next
    # The page only shows the plan; link the plans graph's copy only when one was recorded (cbrs plan).
    data["recorded"] = result.plan is not None and context.kb().describes(result.plan.iri)
    data["graph"] = url_for("plans.graph", task=task, objective=objective)
    return shown


@blueprint.get("/plans/graph.svg")
def graph() -> Response:
    """The service resource graph of the task's composition, with the chosen plan, as SVG."""
    task = request.args.get("task", "").strip()
    objective = request.args.get("objective", "").strip() or default_objective()
    with context.lock():  # pyplot is not thread-safe either
        composed = _composed(task, objective, None)
        if composed.svg is None:
            composed.svg = _svg(composed.result)
    return Response(composed.svg, mimetype="image/svg+xml", headers={"Cache-Control": "no-cache"})


@dataclass
class _Composed:
    """A task's composition by one composer, and its drawing once asked for; in a home of several mobile
    bases, the one-base composition a run would take and the base (``actions.base_choice``), so the page
    never shows a plan that mixes two bases' components."""

    composer: Composer
    result: CompositionResult
    base: BaseChoice | None = None
    svg: bytes | None = None


def _composed(task: str, objective: str, shown: Page | None) -> _Composed:
    """The task's composition, made once per store generation and composer: the page and its drawing
    (``/plans/graph.svg``, asked for by the page) each composed afresh, 0.7 s and more on OWLS-TC. The
    composer is made again when a component's lease lapses (:class:`cbrs.bridge_services.Composers`),
    which no store write marks, so a kept composition counts only with the composer that made it.
    Call with ``context.lock()`` held, which guards the kept compositions too."""
    from cbrs.actions.base_choice import choose_in_map
    from cbrs.actions.composer import Objective
    from cbrs.actions.errors import UnknownTaskError
    from cbrs.task_names import task_iri

    objectives = _objectives()
    if objective not in objectives:
        raise FormError({"objective": f"{objective!r} is not one of {', '.join(objectives)}"}, page=shown)
    if not task:
        raise FormError({"task": "choose a task: a requirement or an action"}, page=shown)
    composer = context.composers().get(Objective(objective))
    kept: dict[tuple[str, str], _Composed] = context.per_generation("plans_composed", dict)
    try:
        iri = task_iri(context.kb(), task_name(task))
        found = kept.get((objective, iri))
        if found is None or found.composer is not composer:
            result, base = choose_in_map(composer, iri, composer.compose(iri))
            found = kept[(objective, iri)] = _Composed(composer, result, base)
        return found
    except UnknownTaskError as error:  # says what was meant and how to type every known task
        raise FormError({"task": str(error)}, page=shown) from None


_IRI_BEFORE_QUESTION = re.compile(r"""(https?://[^\s<>"'?]+)\?""")


@blueprint.app_template_filter("note_text")
def note_text(text: str) -> str:
    """A composition's note (``CompositionResult.notes``) with its IRIs as the pages name them: as
    :func:`short_text` does, and an IRI a question mark ends ("did you mean ...#PutCupOnMat?"), which
    :func:`short_text` takes as part of it and leaves whole."""
    return short_text(_IRI_BEFORE_QUESTION.sub(lambda found: f"{short(found.group(1))}?", text))


@blueprint.app_template_filter("plan_part")
def plan_part(part: str) -> str:
    """A part of a decomposed plan as the pages name it: a sub-action by :func:`short`, a goal's part (the
    task's IRI and ``/goal1``) by the task's short name and its goal, which :func:`short` leaves whole."""
    task, slash, goal = part.rpartition("/")
    if slash and goal.startswith("goal") and goal.removeprefix("goal").isdigit():
        return f"{short(task)}/{goal}"
    return short(part)


DRAWING_MODULE = "cbrs.actions.draw"


@functools.cache
def _load_drawing_library() -> threading.Thread | None:
    """Import the drawing's module, and matplotlib with it, in the background once the plans page is
    shown (its form, or a plan after it is composed). The import took 1.1 to 1.5 s of the first drawing,
    with the store lock held; the page's ``<img>`` (lazy: asked when scrolled to) now finds it done or
    under way. Once a process; None without matplotlib."""
    if not installed("eval"):
        return None
    thread = threading.Thread(target=importlib.import_module, args=(DRAWING_MODULE,), name="cbrs-drawing", daemon=True)
    thread.start()
    return thread


def _svg(result: CompositionResult) -> bytes:
    require("eval", "the plan's drawing")
    from cbrs.actions.draw import draw  # matplotlib is slow to import; only when a drawing is asked for

    with tempfile.TemporaryDirectory(prefix="cbrs-srg-") as folder:
        return draw(result, Path(folder) / "graph.svg", qualifier).read_bytes()


def qualifier(iri: str) -> str:
    """What tells apart two components of one local name in the plans' pictures: the prefix the pages
    show (declared or derived, ``mapGerman_service``), else the file part of the IRI."""
    prefix, colon, _ = short(iri).partition(":")
    if colon and short(iri) != iri:
        return prefix
    return tail_parts(iri)[0].rstrip("#") or file_qualifier(iri)


def task_options() -> dict[str, list[dict[str, str | None]]]:
    """What can be planned: the requirements, and the action classes that have sub-actions; read once per
    store generation (reading every requirement took 1.5 s of each plans page on OWLS-TC)."""
    return context.per_generation("plan_tasks", _read_tasks)


def _read_tasks() -> dict[str, list[dict[str, str | None]]]:
    from cbrs.actions.model import ActionLibrary

    kb = context.kb()
    with context.lock():
        requirements = kb.requirements()
        library = ActionLibrary.from_kb(kb)
    # the names go back as ?task=, which the planner reads with the declared prefixes only; ``shown`` is
    # what the pages show (a lab's own namespace by its derived prefix: the list showed its full IRIs)
    return {
        "requirements": [
            {"name": shorten(r.iri), "shown": short(r.iri), "label": r.label}
            for r in sorted(requirements, key=lambda r: r.iri)
        ],
        "actions": [
            {"name": shorten(a.iri), "shown": short(a.iri), "label": a.label}
            for a in sorted(library, key=lambda a: a.iri)
            if a.sub_actions
        ],
    }


def _shown_task(task: str, selected: str | None) -> str:
    """The task as every page and a run name it (:func:`shown_task`), ``selected`` the option it means."""
    return shown_task(task, expand(selected) if selected is not None else None)


def _selected(task: str, options: dict[str, list[dict[str, str | None]]]) -> str | None:
    """The option a task name means: a bare name is a requirement first, as for ``resolve_task``; a task
    of a lab's own namespace by its bare name, its derived prefixed name or its IRI (the form showed
    "(choose)" above such a task's plan)."""
    for t in (t for group in ("requirements", "actions") for t in options[group]):
        name, shown = str(t["name"]), str(t["shown"])
        if task in (name, shown, shown.partition(":")[2], name.partition(":")[2] if "://" not in name else None):
            return name
    return None


def _composition(result: CompositionResult) -> dict[str, Any]:
    """``cbrs plan --json``'s shape, with each binding's source said in words for the page."""
    found = result.to_dict()
    for step in found.get("steps", []):
        for binding in (*step["inputs"], *step["preconditions"]):
            binding["source"] = _source(binding)
    for goal in found.get("goals", []):
        goal["source"] = _source(goal)
    return found


def _source(binding: dict[str, Any]) -> str:
    origin = binding["from"]
    where = "requirement" if "step" not in origin else f"#{origin['step']}"
    return f"{where}.{origin['name']}" if binding["role"] == "input" else where


def _flow(composition: dict[str, Any]) -> Markup | None:
    """The plan's data flow as a picture: the requirement on top, each step one row below the lowest
    step it takes an input or a precondition from, the goals at the bottom. Solid arrows carry inputs
    (the input's name beside the head), dashed ones preconditions and goals."""
    steps = composition.get("steps") or []
    if not steps:
        return None
    names = shown_names({c for step in steps for c in (step["component"], *step["alternatives"])}, qualifier)
    depth: dict[int, int] = {}
    edges: list[diagram.Edge] = []
    for step in steps:
        index = step["index"]
        sources = [b["from"].get("step") for b in (*step["inputs"], *step["preconditions"])]
        depth[index] = 1 + max((depth.get(s, 0) for s in sources if s is not None), default=0)
        for binding in (*step["inputs"], *step["preconditions"]):
            source = binding["from"].get("step")
            dashed = binding["role"] != "input"
            edges.append(
                diagram.Edge(
                    f"step-{source}" if source is not None else "requirement",
                    f"step-{index}",
                    "" if dashed else binding["name"],
                    dashed=dashed,
                    note=f"{binding['name']} ← {binding['source']}"
                    + (f" ({binding['degree']})" if binding.get("degree") else ""),
                )
            )
    for goal in composition.get("goals") or []:
        source = goal["from"].get("step")
        key = f"step-{source}" if source is not None else "requirement"
        note = short_text(f"{goal['name']} ← {goal['source']}")  # a lab's class by its prefix, as home:'s
        edges.append(diagram.Edge(key, "goals", dashed=True, note=note))
    task = display_text(composition["task"])
    rows: list[list[diagram.Box]] = [
        [diagram.Box("requirement", task, f"the requirement {composition['task']}", None, "end")]
    ]
    for level in range(1, max(depth.values()) + 1):
        rows.append(
            [
                diagram.Box(
                    f"step-{step['index']}",
                    f"#{step['index']} {two_lines(names[step['component']])}",
                    f"{step['component']}" + (f": {step['label']}" if step.get("label") else ""),
                    f"#step-{step['index']}",
                )
                for step in steps
                if depth[step["index"]] == level
            ]
        )
    if composition.get("goals"):
        rows.append([diagram.Box("goals", "goals", "the effects the requirement asks for", None, "end")])
    return diagram.layered(
        rows, edges, f"Data flow of the plan for {task}", f"{len(steps)} steps in {len(rows) - 1} rows", "flow"
    )
