"""The task editor: write a task in Turtle, check it and see its plan, save it, then run it from the tasks page.

A thin layer over :mod:`cbrs.task_drafts`: "Check and plan" parses and checks the text as ``cbrs load
--graph requirements`` would (writing nothing) and composes it as ``cbrs plan`` does; "Save as task" writes
it into graph:requirements in one update. A save is a write of the store: it needs the update token
(``Authorization: Bearer``, or the page's token field), and a browser's request must come from this
server's own pages (:func:`cbrs.web.tasks.from_own_page`), as a run's start does.
"""

from __future__ import annotations

import difflib
import hashlib
from typing import TYPE_CHECKING, Any

from flask import Blueprint, Response, request, url_for
from flask.sansio.blueprints import BlueprintSetupState
from werkzeug.exceptions import NotFound

from cbrs import task_drafts
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.sparql_service import UpdateForbiddenError
from cbrs.task_drafts import DraftError, DraftShapeError, TaskDraft
from cbrs.web import context
from cbrs.web.links import short, use_text_prefixes
from cbrs.web.pages import FormError, Page, page, wants_json
from cbrs.web.plans import _composition, _flow, _svg, default_objective
from cbrs.web.prefixes import derived
from cbrs.web.sparql import bearer_token, typed_token_refusal
from cbrs.web.tasks import from_own_page

if TYPE_CHECKING:
    from cbrs.actions.composer import CompositionResult

blueprint = Blueprint("task_editor", __name__)

DEFAULTS = {
    "CBRS_TASK_EXAMPLE": "RobotSelfPosition",  # the bundled requirement the editor starts from (paper Table 2)
    "CBRS_TASK_EXAMPLE_NAME": "MyRobotSelfPosition",  # ... renamed, so that it saves as a new task
}
FIELDS = ("turtle", "action", "replace")
EXAMPLE_BODY = '{"turtle": "req:MyTask a cbrs:Requirement ; ...", "action": "check"}'
KEPT = 16  # checked drafts whose composition the drawing (/tasks/new/graph.svg) may still ask for


@blueprint.record_once
def _defaults(state: BlueprintSetupState) -> None:
    for name, value in DEFAULTS.items():
        state.app.config.setdefault(name, value)


@page(blueprint, "/tasks/new", negotiate=True, methods=["GET", "POST"])
def task_editor() -> Page:
    """The editor, prefilled with an example; a POST checks and plans the text (``action=check``) or saves
    it (``action=save``, 201 with ``Location`` the tasks page with the task chosen)."""
    from flask import current_app

    form = _form()
    if not form["turtle"] and request.method == "GET":
        config = current_app.config
        form["turtle"] = task_drafts.example(config["CBRS_TASK_EXAMPLE"], config["CBRS_TASK_EXAMPLE_NAME"])
    shown_form = {name: value for name, value in form.items() if name != "token"}  # never sent back
    data: dict[str, Any] = {"form": shown_form, "tasks_page": url_for("tasks.tasks")}
    if request.method != "POST" or not wants_json():  # a program posting a task has them from the GET
        data["prefixes"] = PREFIXES
    shown = Page("task_editor.html", "New task", data)
    if request.method != "POST":
        return shown
    if not form["turtle"].strip():
        raise FormError({"turtle": "write a task (a cbrs:Requirement) in Turtle"}, page=shown)
    saving = form["action"] == "save"
    use_text_prefixes(task_drafts.declared_prefixes(form["turtle"]))  # a lab's first task: lab14:FetchMyMug
    try:
        if saving:
            from_own_page("saved")
            token = bearer_token() or form["token"] or None
            context.sparql().check_token(token)  # first: a page without the token learns nothing of the store
        with context.lock():
            draft = task_drafts.read(context.kb(), form["turtle"], _prefixes())
            if saving:
                replaced = task_drafts.save(context.sparql(), draft, token, form["replace"])
    except UpdateForbiddenError as error:
        return _refused(shown, error.http_status, "forbidden", typed_token_refusal(error, form["token"]), field="token")
    except DraftShapeError as error:
        problems = [{"message": p.message, "term": p.term, "line": p.line} for p in error.problems]
        return _refused(shown, error.http_status, error.kind, str(error), line=error.line, problems=problems)
    except DraftError as error:
        field = "replace" if isinstance(error, task_drafts.TaskExistsError) else "turtle"
        return _refused(shown, error.http_status, error.kind, str(error), field=field, line=error.line)
    data["task"] = _task(draft)
    if saving:
        return _saved(shown, draft, replaced)
    _planned(shown, draft)
    return shown


@blueprint.get("/tasks/new/graph.svg")
def graph() -> Response:
    """The service resource graph of a draft checked lately (``draft=`` the key its check gave)."""
    key = request.args.get("draft", "")
    kept: dict[str, CompositionResult] = context.per_generation("draft_compositions", dict)
    result = kept.get(key)
    if result is None:
        raise NotFound(f"no task checked lately has the key {key!r}: check the task again to draw its plan")
    with context.lock():  # pyplot is not thread-safe
        svg = _svg(result)
    return Response(svg, mimetype="image/svg+xml", headers={"Cache-Control": "no-cache"})


def _form() -> dict[str, Any]:
    if request.method == "POST" and request.is_json:
        body = request.get_json(silent=True)
        if not isinstance(body, dict):
            raise FormError({"body": f"send a JSON object, e.g. {EXAMPLE_BODY}"})
        unknown = [name for name in body if name not in FIELDS]
        if unknown:
            near = difflib.get_close_matches(unknown[0], FIELDS, n=1)
            meant = f"did you mean {near[0]!r}? " if near else ""
            raise FormError({unknown[0]: f"no such field; {meant}the editor takes {', '.join(FIELDS)}"})
        values = {
            "turtle": str(body.get("turtle", "")),
            "action": str(body.get("action", "check")),
            "replace": body.get("replace") is True,
            "token": "",
        }
    else:
        source = request.form if request.method == "POST" else request.args
        values = {
            "turtle": source.get("turtle", ""),
            "action": source.get("action", "check").strip(),
            "replace": source.get("replace") in ("1", "on", "true"),
            "token": source.get("token", "").strip(),
        }
    if values["action"] not in ("check", "save"):
        raise FormError({"action": f"{values['action']!r} is not check or save"})
    return values


def _prefixes() -> dict[str, str]:
    """The prefixes a task may use without declaring them: cbrs's own and those derived for the store's
    other namespaces (as the pages show its names)."""
    return {**derived(), **PREFIXES}


def _task(draft: TaskDraft) -> dict[str, Any]:
    name = shorten(draft.iri)
    return {
        "iri": draft.iri,
        "name": name,
        "shown": short(draft.iri),
        "label": draft.requirement.label,
        "exists": draft.exists,
    }


def _planned(shown: Page, draft: TaskDraft) -> None:
    """The draft's plan as the plans page shows one: its steps, data flow and drawing, or why none."""
    objective = default_objective()
    with context.lock():
        from cbrs.actions.composer import Objective

        composer = context.composers().get(Objective(objective))
        result, base = task_drafts.plan(composer, draft)  # several mobile bases: the one a run would choose
        kept: dict[str, CompositionResult] = context.per_generation("draft_compositions", dict)
    key = hashlib.sha256(draft.text.encode("utf-8")).hexdigest()[:16]
    kept.pop(key, None)
    kept[key] = result
    while len(kept) > KEPT:
        kept.pop(next(iter(kept)))
    composition = _composition(result)
    shown.title = f"New task: {short(draft.iri)}, {composition['status']}"
    shown.data["composition"] = composition
    shown.data["base"] = base.to_dict() if base is not None else None  # as the plans page says it
    shown.data["undeclared"] = [
        {"term": short(term), "line": task_drafts.line_of(draft.text, short(term))}
        for u in result.unsatisfied
        for term in u.undeclared
    ]
    if not wants_json():
        shown.data["flow"] = _flow(composition)
        shown.data["graph"] = url_for("task_editor.graph", draft=key)


def _saved(shown: Page, draft: TaskDraft, replaced: int) -> Page:
    name = shorten(draft.iri)
    run = url_for("tasks.tasks", task=name)
    shown.status = 201
    shown.headers["Location"] = run
    shown.title = f"New task: {short(draft.iri)} saved"
    shown.data["saved"] = {"iri": draft.iri, "name": name, "replaced": bool(replaced), "run": run}
    return shown


def _refused(shown: Page, status: int, kind: str, message: str, field: str = "turtle", **extra: Any) -> Page:
    """The editor again, the text as sent, with what is wrong beside the field at fault."""
    shown.status = status
    shown.data.update(error=kind, message=message, **extra)
    shown.data["errors"] = {field: message}
    return shown
