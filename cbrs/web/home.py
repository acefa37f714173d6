"""The home page of the semantic map: the home drawn from above (:mod:`cbrs.home_plan`), a table of its
things, its people with whether a task for each runs (:func:`kb.person_choice.people_check`, what ``cbrs
home`` says), and what stops the simulation building it, before anything runs."""

from __future__ import annotations

from typing import Any

from flask import Blueprint, Response
from markupsafe import Markup

from cbrs.home_plan import MOVED, HomeSurvey, survey
from cbrs.kb.person_choice import people_check
from cbrs.kb.semantic_map import local_name
from cbrs.web import context
from cbrs.web.links import iri_url, short
from cbrs.web.pages import Page, page, wants_json

blueprint = Blueprint("home", __name__)


def _survey() -> HomeSurvey:
    with context.lock():  # the map reader goes through the knowledge base's caches
        return survey(context.kb())


@page(blueprint, "/home")
def home() -> Page:
    """Always 200: a map that cannot be read or built is this page's subject, said in ``problem``."""
    found = _survey()
    data: dict[str, Any] = {
        "verdict": found.verdict,
        "problem": _problem(found),
        "counts": found.counts(),
        "counted": found.counted(),
        "people": found.people(),
        "mobile_robots": found.bases(),
        "warnings": found.warnings(),
        "persons": [],
        "things": [],
        "picture": None,
        "moved": MOVED,
    }
    if found.semantic_map is not None:
        data["persons"] = [checked.to_dict() for checked in people_check(found.semantic_map)]
        picture = found.picture(link=iri_url)
        data["things"] = [
            entry.to_dict() | {"shown": short(entry.iri), "classes": [_shown(c) for c in entry.classes]}
            for entry in picture.entries
        ]
        data["picture"] = {"svg": "/home.svg", "width": picture.width, "height": picture.height}
        if not wants_json():
            data["svg"] = Markup(picture.svg)  # built from escaped text only (cbrs.home_plan)
    return Page("home.html", "The home", data)


@blueprint.get("/home.svg")
def home_svg() -> Response:
    """The picture alone; 404 with the reader's message when the map cannot be read."""
    found = _survey()
    if found.semantic_map is None:
        return Response(str(found.problem), status=404, mimetype="text/plain")
    svg = found.picture(link=iri_url).svg
    return Response(svg, mimetype="image/svg+xml", headers={"Cache-Control": "no-cache"})


def _problem(found: HomeSurvey) -> dict[str, str | None] | None:
    if found.problem is None:
        return None
    thing: str | None = getattr(found.problem, "thing", None)
    return {
        "kind": type(found.problem).__name__,
        "message": str(found.problem),
        "thing": thing,
        "name": local_name(thing) if thing else None,
    }


def _shown(concept: str) -> str:
    """A thing's class as the pages show it: a lab's by its derived prefix (``lab10:ReadingLamp``), not its
    IRI; the declared prefixes' as the map reader wrote them."""
    return short(concept) if "://" in concept else concept
