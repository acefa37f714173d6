"""The ``cbrs`` commands that keep a store over months: ``export`` and ``restore`` (:mod:`kb.backup`), and
``update``, a SPARQL update with what it changed said graph by graph (:mod:`kb.update_report`), which
takes the store's derived prefixes as ``cbrs query`` does (:func:`cbrs.kb.sparql_hints.store_prefixes_used`)."""

from __future__ import annotations

import json
import re
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import click
import pyoxigraph as ox

from cbrs import __version__
from cbrs.app import App, pass_app
from cbrs.cli_interrupts import HeldInterrupts
from cbrs.cli_notes import no_store_at
from cbrs.graph_names import graph_hint
from cbrs.kb import KnowledgeBase
from cbrs.kb.backup import (
    DEFAULT,
    Backup,
    BackupError,
    NotAnExportError,
    check_declarations,
    export_format,
    read_backup,
)
from cbrs.kb.colour_risk import ColourRisk, colour_risks
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.errors import QuerySyntaxError, StoreEvaluationError, UnknownGraphError, without_password
from cbrs.kb.namespaces import PREFIXES, GraphName, shorten
from cbrs.kb.sparql_hints import (
    declared,
    explain_syntax_error,
    one_line_up,
    operation_kind,
    store_prefixes_used,
    unexplained,
)
from cbrs.kb.sparql_lexemes import HIDING
from cbrs.kb.store import refuse_inserted_blank_nodes
from cbrs.kb.undeclared_classes import MapTypes, UndeclaredClass, written_undeclared_classes
from cbrs.kb.update_delta import DataOperation, data_operations
from cbrs.output import ProgressLine

_GRAPH_HELP = "A graph to take (repeatable): " + ", ".join(g.value for g in GraphName) + ", or a full IRI."
_FORMAT_CHOICE = click.Choice(["nquads", "trig"])


@click.command()
@click.argument("file", metavar="FILE|-")
@click.option("--graph", "graphs", multiple=True, metavar="NAME|IRI", help=_GRAPH_HELP + " Default: every graph.")
@click.option(
    "--format",
    "fmt",
    type=_FORMAT_CHOICE,
    help="Override the format the name says (.nq N-Quads, .trig TriG, either with .gz); - is N-Quads.",
)
@click.option("--json", "as_json", is_flag=True, help="Print what was exported as JSON (on standard error with -).")
@pass_app
def export(app: App, file: str, graphs: tuple[str, ...], fmt: str | None, as_json: bool) -> None:
    """Write the whole store (every named graph) to FILE, or - for standard output, as a cbrs export: the
    quads, then a manifest that cbrs restore checks (docs/backup.md)."""
    rdf_format = export_format(file, fmt)
    shown = ProgressLine()
    try:
        report = app.kb.export(file, rdf_format, list(graphs) or None, shown)
    except (UnknownGraphError, BackupError) as error:  # --graph graph:mapp: "no graph" said no more
        hint = graph_hint(graphs, app.kb.store.graphs()) if graphs else None
        if hint is not None:
            error.add_note(hint)
        raise
    finally:
        shown.clear()
    if as_json:
        said: dict[str, Any] = {"file": file, "format": "trig" if rdf_format == ox.RdfFormat.TRIG else "nquads"}
        said["total"] = report.total
        said["graphs"] = [{"graph": g or None, "triples": n} for g, n in report.triples.items()]
        click.echo(json.dumps(said, indent=2), err=file == "-")
        return
    where = "standard output" if file == "-" else file
    counts = ", ".join(f"{n} in {_graph_name(graph)}" for graph, n in sorted(report.triples.items()))
    click.echo(
        f"exported {report.total} triples from {without_password(app.kb.store.location)} to {where}: {counts}",
        err=file == "-",
    )


@click.command()
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--graph",
    "graphs",
    multiple=True,
    metavar="NAME|IRI",
    help=_GRAPH_HELP + " Only these graphs are replaced, by the file's; the others are left. Default: the "
    "whole store is replaced.",
)
@click.option("--format", "fmt", type=_FORMAT_CHOICE, help="Override the format the file's name says.")
@click.option("--yes", is_flag=True, help="Do not ask for confirmation (a terminal is asked; a script is not).")
@click.option(
    "--force",
    is_flag=True,
    help="Restore a file that is not a whole cbrs export (no manifest, counts that differ, cbrs's own "
    "graphs missing), or one that holds a class under a home:/cbrs:/act: term it does not declare, as it is.",
)
@click.option("--json", "as_json", is_flag=True, help="Print what was restored as JSON.")
@pass_app
def restore(
    app: App, file: Path, graphs: tuple[str, ...], fmt: str | None, yes: bool, force: bool, as_json: bool
) -> None:
    """Replace the store's contents with those of FILE, a cbrs export, all or nothing: a file that does not
    parse, or a write that fails, leaves the store as it was (docs/backup.md)."""
    shown = ProgressLine()
    try:
        backup = read_backup(file, export_format(str(file), fmt), shown)
    except KeyboardInterrupt:  # click would say "Aborted!", and a person would wonder what was written
        raise click.ClickException(f"{file}: Ctrl-C while reading it; nothing was restored") from None
    finally:
        shown.clear()
    try:
        problems = backup.problems(list(graphs) or None)
        if problems and not force:  # before the store is opened: a new one is not created for nothing
            raise NotAnExportError(backup.source, problems)
    except (UnknownGraphError, NotAnExportError) as error:  # --graph graph:mapp: which of the file's it may mean
        hint = graph_hint(graphs, [graph for graph in backup.quads if graph != DEFAULT]) if graphs else None
        if hint is not None:
            error.add_note(hint)
        raise
    if not force and not graphs and no_store_at(app.store_location):
        check_declarations(None, backup)  # before a new store is made there for nothing
    # a whole restore replaces everything: a new store is not seeded first, an old one not upgraded first
    kb = app.open_kb(seed=bool(graphs))
    if problems:
        click.echo(f"note: {file}: {'; '.join(problems)}; restored all the same (--force)", err=True)
    _confirm(app, backup, graphs, yes)
    shown = ProgressLine()
    with HeldInterrupts() as interrupts:

        def progress(stage: str, done: int, total: int) -> None:
            if stage.startswith("writing"):
                interrupts.hold("restoring the store")
            shown(stage, done, total)

        try:
            report = kb.restore(backup, list(graphs) or None, force, progress)
        except KeyboardInterrupt:
            raise click.ClickException(_stopped(kb.store.location, interrupts.held)) from None
        finally:
            shown.clear()
    refreshed = report.entailed_refreshed  # graph:entailed worked out, not restored
    if interrupts.interrupted:
        click.echo("cbrs: the Ctrl-C came after the write had begun: the restore stands, as follows", err=True)
    restored = sum(n for graph, n in report.restored.items() if graph != GraphName.ENTAILED.iri or not refreshed)
    if as_json:
        rows = [
            {"graph": graph or None, "triples": report.restored.get(graph, 0), "before": report.before.get(graph)}
            for graph in sorted(set(report.before) | set(report.restored))
        ]
        left = [{"graph": graph or None, "triples_in_file": n} for graph, n in sorted(report.skipped.items())]
        said = {"file": str(file), "restored": restored, "graphs": rows, "left": left}
        click.echo(json.dumps(said | {"entailed_refreshed": refreshed}, indent=2))
        return
    click.echo(f"restored {restored} triples from {file} into {without_password(kb.store.location)}")
    for graph in sorted(set(report.before) | set(report.restored)):
        was, now = report.before.get(graph), report.restored.get(graph, 0)
        was_text = "absent" if was is None else f"{was} triples"
        click.echo(f"  {_graph_name(graph):<22} {now:>8} triples (was {was_text})")
    for graph, count in sorted(report.skipped.items()):
        click.echo(f"  {_graph_name(graph):<22} left as it was ({count} triples in the file not restored)")
    if report.entailed_refreshed:
        click.echo("graph:entailed worked out afresh from the restored graphs")
    if backup.manifest is not None and backup.manifest.cbrs_version not in ("", __version__):
        click.echo(
            f"the file was exported by cbrs {backup.manifest.cbrs_version}, this is {__version__}: the next command "
            "that opens the store brings it up to the bundled ontologies (docs/backup.md)"
        )


def _confirm(app: App, backup: Backup, graphs: tuple[str, ...], yes: bool) -> None:
    """Ask a person at a terminal before a restore replaces what the store holds; a script is not asked."""
    if yes or not _at_terminal():
        return
    manifest = backup.manifest
    said = (
        f" (exported {manifest.exported_at} by cbrs {manifest.cbrs_version} from {manifest.source})" if manifest else ""
    )
    what = f"graphs {', '.join(graphs)} of" if graphs else "everything in"
    click.confirm(
        f"Replace {what} {without_password(app.kb.store.location)} with the {sum(backup.triples.values())} "
        f"triples of {backup.source}{said}?",
        abort=True,
        err=True,
    )


@click.command()
@click.argument("text", required=False)
@click.option(
    "--file",
    "update_file",
    type=click.File("r", encoding="utf-8"),
    help="Read the update from a .ru file (- for standard input).",
)
@click.option("--json", "as_json", is_flag=True, help="Print what changed as JSON.")
@pass_app
def update(app: App, text: str | None, update_file: Any, as_json: bool) -> None:
    """Run a SPARQL update given as TEXT or from --file, all or nothing; graph:entailed follows, and what
    changed is said graph by graph."""
    if (text is None) == (update_file is None):
        raise click.UsageError("give exactly one of TEXT or --file")
    body = (text if text is not None else update_file.read()).removeprefix("\ufeff")
    if operation_kind(body) == "query":
        raise click.ClickException("this is a SPARQL query, not an update: run it with cbrs query")
    refuse_inserted_blank_nodes(body)  # what cbrs stores it must be able to read back by name
    # the names cbrs prints for this store (lab4:Trolley1) may be written, as cbrs query takes them: their
    # derived prefixes are declared above the text when it uses them and declares them not
    names = StoreNames(lambda: app.kb)
    added = store_prefixes_used(body, lambda: names.prefixes)
    colours = _ColourRisks(app.kb, body)
    operations = data_operations(declared(added, body))  # None: an update by a pattern
    typed = MapTypes(app.kb.store, body) if operations is None else None  # its quads known once it has run
    with HeldInterrupts() as interrupts:
        interrupts.hold("running the update")
        try:
            report = app.kb.update_counted(declared(added, body))
        except QuerySyntaxError as error:
            parsed = unexplained(error)  # the store explained the text run, prologue and all: explained anew
            counted = one_line_up(parsed, body) if added else parsed  # placed in the text as written
            explained = explain_syntax_error(counted, body, "update", names.prefixes)
            explained.add_note("nothing was changed")
            if explained is error:
                raise
            raise explained from error
        except StoreEvaluationError as error:  # the store refused the request whole (one transaction)
            error.add_note("nothing was changed")
            raise
    risks = colours.new()  # (a DELETE/INSERT that repaints changes no size: looked at all the same)
    if as_json:
        changes = [
            {"graph": change.graph or None, "net": change.net, "added": change.added, "removed": change.removed}
            for change in report.changes
        ]
        found: dict[str, Any] = {"exact": report.exact, "counted": report.counted, "changes": changes}
        if risks:
            found["warnings"] = [risk.to_dict() for risk in risks]
        click.echo(json.dumps(found, indent=2))
        return
    for line in report.lines():
        click.echo(line)
    for risk in risks:
        click.echo(f"warning: {risk.text()}", err=True)
    written = typed.undeclared() if typed is not None else _undeclared_in_map(app.kb, operations or ())
    for undeclared in written:
        click.echo(f"warning: {undeclared.text()}", err=True)
    if not report.changed:
        _note_unknown_names(app.kb, body, added)
    if report.changed and not app.kb.store.is_seeded():  # CLEAR ALL, DROP GRAPH graph:ontology
        click.echo(
            "note: graph:ontology is empty now: the next command that opens the store seeds it again with the "
            "bundled data (cbrs restore FILE puts a backup back)",
            err=True,
        )


class _ColourRisks:
    """The things an update leaves painted where the cameras may not tell their colour and were not before
    (:mod:`kb.colour_risk`); looked at only for an update that names a colour or a window's property."""

    _WORDS = re.compile(r"rgba|colourName|ColourWindow|hueCentre|hueTolerance|hueMargin|minSaturation|minBrightness")

    def __init__(self, kb: KnowledgeBase, body: str) -> None:
        self._kb = kb
        self._before = {risk.text() for risk in colour_risks(kb)} if self._WORDS.search(body) else None

    def new(self) -> list[ColourRisk]:
        if self._before is None:
            return []
        return [risk for risk in colour_risks(self._kb) if risk.text() not in self._before]


_PREFIXED = re.compile(r"(?<![\w?$:])([A-Za-z][\w-]*):([A-Za-z_][\w-]*(?:\.[\w-]+)*)")
_DECLARED = re.compile(rf"\bPREFIX\s+([\w-]*):\s*<([^<>\"{{}}|^`\\\x00-\x20]*)>|{HIDING}", re.IGNORECASE)
"""A PREFIX declaration (its prefix and namespace), or a string, IRI or comment that hides one."""


def _undeclared_in_map(kb: KnowledgeBase, operations: Iterable[DataOperation]) -> list[UndeclaredClass]:
    """The classes nothing declares of the quads an update of ground data (``INSERT DATA``) put into graph:map,
    read as :mod:`kb.update_delta` reads them, as ``cbrs load --graph map`` warns of them
    (:mod:`kb.undeclared_classes`); an update by a pattern is read by what it added (``MapTypes``)."""
    inserted = [quad for op in operations if op.insert for quad in op.quads if quad.graph_name == GraphName.MAP.node]
    return written_undeclared_classes(kb.store, inserted)


def _note_unknown_names(kb: KnowledgeBase, body: str, derived: Mapping[str, str]) -> None:
    """After an update that changed no graph's size: say which names it uses that the store mentions
    nowhere (home:yw for home:yaw matched nothing, and "no graph changed" said no more), with the
    nearest names. A prefix is the update's own declaration (``PREFIX lab11: <...>``: a misspelt thing of
    the lab's, lab11:Flsk1, matched nothing too), else cbrs's or one of the store's ``derived`` ones
    declared for it."""
    from cbrs.task_names import near_names  # the action model: only when an update changed nothing

    own = {m.group(1): m.group(2) for m in _DECLARED.finditer(body) if m.group(2) is not None}
    text = re.sub(_DECLARED, " ", body)  # the declarations, strings, IRIs and comments: no names in them
    known = {**PREFIXES, **derived, **own}
    seen = set(map(shorten, kb.store.graphs()))  # a graph's name is mentioned in no triple
    for prefix, local in _PREFIXED.findall(text):
        name = f"{prefix}:{local}"
        if prefix not in known or name in seen:
            continue
        seen.add(name)
        if not kb.describes(known[prefix] + local):
            near = near_names(kb, known[prefix] + local)
            meant = f"; did you mean {' or '.join(near)}?" if near else ""
            click.echo(f"note: nothing in the store mentions {name}{meant}", err=True)


def _stopped(location: str, writing: bool) -> str:
    """What a Ctrl-C left of a restore: nothing before the write; during it (a second Ctrl-C, which stops
    waiting for a remote store), the staging was undone, but a request on its way may still be carried out."""
    if not writing:
        return "Ctrl-C before the write began; nothing was restored"
    return (
        f"Ctrl-C again during the write to {without_password(location)}: the restore was stopped and its staged "
        "batches dropped, but a request the server had already taken may still be carried out: see what the "
        "store holds (cbrs query); a graph under graph:staging/ is inert and cbrs init lists it"
    )


def _at_terminal() -> bool:
    return sys.stdin.isatty()


def _graph_name(graph: str) -> str:
    return shorten(graph) if graph != DEFAULT else "(default graph)"
