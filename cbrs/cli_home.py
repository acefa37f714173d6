"""``cbrs home``: what the semantic map says the home holds, whether the simulation can build it, and
its picture from above (:mod:`cbrs.home_plan`), before anything runs."""

from __future__ import annotations

import json
from pathlib import Path

import click

from cbrs.app import App, pass_app
from cbrs.home_plan import DEFAULT_WIDTH, NO_ROOMS, HomeSurvey, resource_link, survey
from cbrs.kb.namespaces import shorten
from cbrs.kb.person_choice import people_check
from cbrs.kb.semantic_map import local_name
from cbrs.settings import setting


@click.command()
@click.option(
    "--draw",
    "drawing",
    type=click.Path(dir_okay=False, writable=True, path_type=Path),
    help="Write the home from above to this SVG file.",
)
@click.option("--width", type=click.IntRange(min=300), default=DEFAULT_WIDTH, show_default=True, help="Pixels across.")
@click.option(
    "--browser",
    metavar="URL",
    help="Where the drawing's things link to: the browser of a cbrs serve. Default: http://127.0.0.1:PORT "
    "(the port setting).",
)
@click.option("--json", "as_json", is_flag=True, help="Print the summary, the verdict and the things as JSON.")
@pass_app
def home(app: App, drawing: Path | None, width: int, browser: str | None, as_json: bool) -> None:
    """Summarise the home of the semantic map (graph:map) and check it as the simulation builds it.

    Prints the counts of its rooms, furniture, objects, robots, people and cameras, its rooms, its people
    (with what none or several allow), and the home check's verdict; with --draw, writes the home from
    above as SVG. Exits with status 1 when the map cannot be read or the simulation would refuse it (the
    drawing is written all the same when the map can be read: it shows what is there).
    """
    if drawing is not None and drawing.suffix.lower() != ".svg":  # SVG text in a .png: no viewer opens it
        raise click.BadParameter(f"{drawing.name!r} must end in .svg (the drawing is SVG)", param_hint="--draw")
    found = survey(app.kb)
    root = (browser or f"http://127.0.0.1:{setting('port').resolve()}").rstrip("/")
    written = None
    entries = []
    if drawing is not None and found.semantic_map is not None:
        picture = found.picture(width, link=lambda iri: root + resource_link(iri))
        drawing.write_text(picture.svg, encoding="utf-8")
        written = str(drawing)
        entries = [entry.to_dict() for entry in picture.entries]
    if as_json:
        said: dict[str, object] = {
            "verdict": found.verdict,
            "counts": found.counts(),
            "rooms": _rooms(found),
            "drawing": written,
        }
        said["people"] = found.people()
        said["mobile_robots"] = found.bases()
        said["warnings"] = found.warnings()
        said["persons"] = (
            [c.to_dict() for c in people_check(found.semantic_map)] if found.semantic_map is not None else []
        )
        said["notice"] = NO_ROOMS if found.semantic_map is not None and not _rooms(found) else None
        said["problem"] = str(found.problem) if found.problem is not None else None
        if entries:
            said["things"] = entries
        click.echo(json.dumps(said, indent=2))
    else:
        click.echo(_text(found, written))
    if found.problem is not None:
        raise SystemExit(1)


def _rooms(found: HomeSurvey) -> list[dict[str, object]]:
    smap = found.semantic_map
    if smap is None:
        return []
    rooms: list[dict[str, object]] = []
    for iri in sorted(smap.rooms):
        thing = smap.things.get(iri)
        if thing is not None:
            box = thing.box
            rooms.append(
                {
                    "iri": iri,
                    "name": local_name(iri),
                    "classes": [shorten(t) for t in smap.types.get(iri, ())],
                    "extent": [box.min_x, box.max_x, box.min_y, box.max_y],
                    "text": f"x {box.min_x:g} to {box.max_x:g}, y {box.min_y:g} to {box.max_y:g}",
                }
            )
    return rooms


def _text(found: HomeSurvey, written: str | None) -> str:
    smap = found.semantic_map
    if smap is None:
        return f"the semantic map cannot be read: {found.problem}"
    lines = ["home: " + ", ".join(found.counted())]
    rooms = _rooms(found)
    for room in rooms:
        classes = room["classes"]
        kinds = ", ".join(classes) if isinstance(classes, list) else ""
        lines.append(f"  {room['name']} ({kinds}): {room['text']}")
    if not rooms:
        lines.append(f"  {NO_ROOMS}")
    lines.append(f"people: {found.people()}")
    if len(smap.robots) != 1:  # a home with no mobile base, or several: what it allows (one goes without saying)
        lines.append(f"mobile robots: {found.bases()}")
    lines += [f"warning: {warning}" for warning in found.warnings()]
    moved = [iri for iri in found.believed if iri in smap.objects or iri in smap.robots or iri in smap.people]
    if moved:
        lines.append(f"the world graph places {len(moved)} of its things after a run: a drawing shows those that moved")
    if found.problem is None:
        lines.append("check: the simulation can build this home")
    else:
        lines.append(f"check: the simulation would refuse this home: {found.problem}")
    if written and not rooms:
        lines.append(f"drew what the map places, under that notice, to {written}")
    elif written:
        lines.append(f"drew the home from above to {written}")
    return "\n".join(lines)
