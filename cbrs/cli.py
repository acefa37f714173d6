"""The ``cbrs`` command: a thin click layer over :class:`kb.KnowledgeBase`.

Library errors become one-line messages and a non-zero exit here, at the edge, and nowhere else.
"""

from __future__ import annotations

import contextlib
import difflib
import importlib
import json
import os
import re
import shlex
import sys
import traceback
from collections import Counter
from collections.abc import Collection, Iterable, Iterator
from pathlib import Path
from typing import Any

import click
import pyoxigraph as ox

from cbrs import __version__
from cbrs.app import App, parse_iri, pass_app
from cbrs.cli_interrupts import HeldInterrupts
from cbrs.cli_notes import no_store_at, note_new_store, wants_json, with_notes
from cbrs.cli_store import export, restore, update
from cbrs.extras import require
from cbrs.graph_names import graph_hint
from cbrs.isolated_queries import IsolatedQueries, IsolatedResult
from cbrs.kb import Advertisement, KnowledgeBase, KnowledgeBaseError, Requirement, ServiceDescription
from cbrs.kb.catalog import Catalogue, merge
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.described import about_in, complete
from cbrs.kb.engine_faults import sorts
from cbrs.kb.errors import (
    AlreadyRegisteredError,
    NotFoundError,
    QuerySyntaxError,
    RdfParseError,
    UnknownGraphError,
    without_password,
)
from cbrs.kb.liveness import ComponentState
from cbrs.kb.loader import LoadReport, ParsedFile, holds_ontology
from cbrs.kb.namespaces import (
    CBRS,
    OWL,
    PREFIXES,
    GraphName,
    expand,
    is_absolute_iri,
    near_prefixes,
    shorten,
    store_names,
)
from cbrs.kb.skolem import is_skolem
from cbrs.kb.sparql_hints import (
    declared,
    explain_syntax_error,
    first_keyword,
    one_line_up,
    store_prefixes_used,
    unexplained,
)
from cbrs.kb.staged_writes import STAGING
from cbrs.kb.store import EmbeddedStore, QueryResult, Term
from cbrs.output import (
    RESULT_FORMATS,
    Cell,
    ProgressLine,
    fitted_table,
    json_row,
    node_view,
    output_width,
    render_result,
    sorted_lists,
    table,
    term_text,
)
from cbrs.settings import SETTINGS, setting
from cbrs.unmentioned_names import unmentioned_bindings, unmentioned_names

# Commands whose modules import numpy, networkx, the composer or the web server (most of a second at
# start-up): each is imported when it runs or shows its own help. ``cbrs --help`` lists them from the
# first paragraph of their help, kept here (tests/test_scale.py checks it against the commands).
_LAZY_COMMANDS: dict[str, tuple[str, str, str]] = {
    "eval": ("cbrs.cli_reasoner", "eval_group", "Evaluate the matching methods on a test collection."),
    "home": (
        "cbrs.cli_home",
        "home",
        "Summarise the home of the semantic map (graph:map) and check it as the simulation builds it.",
    ),
    "match": (
        "cbrs.cli_reasoner",
        "match",
        "Rank the advertisements against REQUIREMENT: an IRI, prefix:name, or a bare name in req: (RobotSelfPosition).",
    ),
    "plan": (
        "cbrs.cli_actions",
        "plan",
        "Compose a plan for TASK: a requirement or action (req:FetchMyPen, act:RobotArmServeACup, or a bare name).",
    ),
    "run": (
        "cbrs.cli_actions",
        "run",
        "Plan TASK, then execute it in the simulated home, step by step, failing over where needed.",
    ),
    "serve": (
        "cbrs.cli_serve",
        "serve",
        "Serve the knowledge base: SPARQL 1.1 at /sparql on the HTTP port, rosbridge v2 on the bridge port.",
    ),
}


_DECLARED_NAMES_ONLY = frozenset({"serve", "query"})
"""Commands that print names with the declared prefixes only: the server's threads name IRIs for their
clients, and a query's rows are printed as the endpoint gives them. A query's text may still use the
store's derived prefixes (declared above it when it uses them), and a named query's --bind values are
names typed like any command's, so they take the derived ones too."""

_ARGS = "cbrs.subcommand_args"  # ctx.meta: the subcommand's arguments, as typed

_TAKE_NAMES = frozenset({"deregister", "match", "plan", "run", "show"})
"""Commands whose arguments name resources: a name with a derived prefix opens the store to read it.
The others use the derived prefixes only once they have opened the store themselves."""


class _Group(click.Group):
    """Turns library errors into click's one-line error and exit status 1; imports the commands of
    ``_LAZY_COMMANDS`` only when they are used."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*self.commands, *_LAZY_COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in _LAZY_COMMANDS:
            module, attribute, _ = _LAZY_COMMANDS[cmd_name]
            self.add_command(getattr(importlib.import_module(module), attribute), cmd_name)
        return self.commands.get(cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """As click lists the commands, with a stand-in carrying the help of each command not imported."""
        commands = [
            self.commands.get(name) or click.Command(name, help=_LAZY_COMMANDS[name][2])
            for name in self.list_commands(ctx)
        ]
        shown = [(command.name or "", command) for command in commands if not command.hidden]
        if not shown:
            return
        limit = formatter.width - 6 - max(len(name) for name, _ in shown)
        with formatter.section("Commands"):
            formatter.write_dl([(name, command.get_short_help_str(limit)) for name, command in shown])

    def invoke(self, ctx: click.Context) -> Any:
        args = list(ctx.args)  # the subcommand's own, before they are parsed (or fail to be)
        ctx.meta[_ARGS] = args
        try:
            try:
                return super().invoke(ctx)
            except KnowledgeBaseError as error:
                raise click.ClickException(with_notes(error)) from error
            except ValueError as error:  # settings from the environment
                raise click.ClickException(with_notes(error)) from error
        except click.ClickException as error:
            if wants_json(args, ctx.invoked_subcommand):
                click.echo(json.dumps({"error": error.format_message(), "exit_code": error.exit_code}))
            raise


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="cbrs")
@click.option(
    "--store",
    metavar="PATH|:memory:|URL",
    help=setting("store").help + f" [env {setting('store').env}; default: the user data directory]",
)
@click.pass_context
def cli(ctx: click.Context, store: str | None) -> None:
    """cbrs: a knowledge base that lets service robots find and use the services around them."""
    location = setting("store").resolve(store)
    app = App(store_location=location)
    ctx.obj = app
    ctx.call_on_close(app.close)
    if ctx.invoked_subcommand not in _DECLARED_NAMES_ONLY:  # names as the browser shows them (docs/web.md)
        takes_names = ctx.invoked_subcommand in _TAKE_NAMES
        json_out = wants_json(ctx.meta.get(_ARGS, []), ctx.invoked_subcommand)
        names = StoreNames(lambda: app.kb if takes_names else app.opened_kb, shortens=not json_out)
        ctx.with_resource(store_names(names))
    # a restore into a new directory means to make it, and seeds nothing: it says each graph was absent
    if ctx.invoked_subcommand not in (None, "init", "settings", "restore") and no_store_at(location):
        ctx.call_on_close(lambda: note_new_store(location))


@cli.command()
@pass_app
def init(app: App) -> None:
    """Create the store and seed it with the bundled ontologies, advertisements and requirements."""
    kb = app.kb  # opening seeds a new store
    stats = kb.statistics()
    click.echo(f"store: {without_password(kb.store.location)}")
    for graph in GraphName:
        click.echo(f"  {shorten(graph.iri):<20} {stats.get(graph.iri, 0):>7} triples")
    for left, count in sorted(stats.items()):
        if left.startswith(STAGING):  # not every other graph: Virtuoso lists its own system graphs
            click.echo(f"  {left}  {count} triples{_left_behind(left)}")
    click.echo(f"{len(kb.select('advertisements'))} advertisements, {len(kb.select('requirements'))} requirements")


def _left_behind(graph: str) -> str:
    """What to do about a staging graph a remote write left when it failed with its server gone
    (kb/staged_writes.py): it holds only wrapped statements, so nothing reads it, but it stays."""
    return f" (left by a write that failed: inert; the update DROP SILENT GRAPH <{graph}> removes it)"


@cli.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option(
    "--graph",
    metavar="NAME|IRI",
    help="Named graph for the files' triples: " + ", ".join(g.value for g in GraphName) + " or a full IRI. "
    "Default: ontology for files that declare classes or properties, requirements for requirements, "
    "services otherwise (OWL-S files: services). OWL-S files loaded into requirements become requirements.",
)
@click.option(
    "--catalog",
    "catalogs",
    multiple=True,
    metavar="DIR|FILE",
    type=click.Path(exists=True, path_type=Path),
    help="Resolve owl:imports (and the ontologies of OWL-S parameter types) to local files: a folder of "
    "ontologies (with the catalog-v001.xml Protégé keeps in it, if any), an OASIS catalog-v001.xml or a two-column "
    "TSV. Nothing is fetched from the network.",
)
@click.option(
    "--replace",
    is_flag=True,
    help="With --graph map: the files become the whole semantic map, your own home in place of the bundled "
    "one, in one transaction; refused, the map as it was, unless they make a home the simulation can build "
    '(docs/tasks.md, "A home of your own").',
)
@pass_app
def load(app: App, files: tuple[Path, ...], graph: str | None, catalogs: tuple[Path, ...], replace: bool) -> None:
    """Load RDF files (Turtle, RDF/XML, OWL, N-Triples, N-Quads, TriG, JSON-LD) and OWL-S services, all
    or nothing. A directory stands for the RDF and OWL-S files directly inside it."""
    catalogue = merge([Catalogue.open(path) for path in catalogs]) if catalogs else None
    shown = ProgressLine()
    with HeldInterrupts() as interrupts:

        def progress(stage: str, done: int, total: int) -> None:
            if stage.startswith("writing"):
                interrupts.hold(stage)
            shown(stage, done, total)

        try:
            with _undeclared_prefixes():
                report = app.kb.load(list(files), graph, catalogue, progress, replace=replace)
        except UnknownGraphError as error:  # --graph mapp: which graph it may mean
            _note_near_graphs(error, [graph or ""], app.kb.store.graphs(), own_count=True)
            raise
        finally:
            shown.clear()
    if interrupts.interrupted:
        click.echo("cbrs: the Ctrl-C came after the write had begun: the load stands, as follows", err=True)
    for item in report.files:
        what = _loaded_what(item)
        click.echo(f"loaded {item.source}: {what}{_into(item)}{_mended(item)}")
    if graph is None:
        _note_defaulted(report)
    _note_near_namespaces(report)
    for line in _load_summary(report, app.kb.store):
        click.echo(line)
    for line in _added_summary(report):
        click.echo(line)
    _warn_colours(app.kb, report)
    _warn_undeclared_classes(app.kb, report)
    for graph, count in report.removed.items():
        click.echo(f"replaced {shorten(graph)}: took out {_plural(count, 'triple')} the files do not give")
    for graph, count in report.kept.items():
        robots = ", ".join(shorten(iri) for iri in report.kept_robots)
        click.echo(f"kept in {shorten(graph)}: the robots' own descriptions ({robots}; {_plural(count, 'triple')})")


def _warn_colours(kb: Any, report: LoadReport) -> None:
    """Say on standard error which things the load painted where the cameras may not tell their colour
    (:mod:`kb.colour_risk`): at a window's edge, outside every window, too grey or dark. Loaded all the
    same: it is not wrong, only risky (an apple at the edge of green was seen in part, and dropped)."""
    from cbrs.kb.colour_risk import written_colour_risks

    for risk in written_colour_risks(kb, (quad for item in report.files for quad in item.quads)):
        click.echo(f"warning: {risk.text()}", err=True)


def _warn_undeclared_classes(kb: Any, report: LoadReport) -> None:
    """Say on standard error which things a load into the map states to be of a class that nothing in the
    store declares (:mod:`kb.undeclared_classes`). Loaded all the same: a lab's class may come in a later
    file. Other graphs are left alone (an OWL-S collection's services are of classes of ontologies it does
    not load)."""
    from cbrs.kb.undeclared_classes import written_undeclared_classes

    quads = (quad for item in report.files if item.graph == GraphName.MAP.iri for quad in item.quads)
    for found in written_undeclared_classes(kb.store, quads):
        click.echo(f"warning: {found.text()}", err=True)


_UNDECLARED = re.compile(r"The prefix ([\w.-]*): has not been declared")
"""Oxigraph's Turtle and TriG parsers' words for a prefix used and not declared."""


@contextlib.contextmanager
def _undeclared_prefixes() -> Iterator[None]:
    """A file that did not parse for a prefix it uses and does not declare: said with the fix."""
    try:
        yield
    except RdfParseError as error:
        hint = _undeclared_hint(error.message)
        if not hint:
            raise
        raise click.ClickException(with_notes(error) + hint) from error


def _undeclared_hint(message: str) -> str:
    """For a prefix a file uses without declaring it: its declaration when cbrs knows the prefix (the
    file's own @prefix line is mistyped or missing), else the known prefixes nearest it (hme: for home:)."""
    found = _UNDECLARED.search(message)
    if found is None:
        return ""
    prefix = found.group(1)
    if prefix in PREFIXES:
        return f"; declare it: @prefix {prefix}: <{PREFIXES[prefix]}> ."
    near = near_prefixes(prefix)
    meant = f"did you mean {' or '.join(p + ':' for p in near)}? " if near else ""
    return f"; {meant}(a file declares each prefix it uses: @prefix {prefix}: <IRI> .)"


def _note_near_namespaces(report: LoadReport) -> None:
    """Say on standard error which namespaces a file names things in that are one slip from one of
    cbrs's (``https://w3id.org/cbrs/hom#``): the file parses and loads, and its things are of no class
    the store knows, which nothing else said."""
    known = list(PREFIXES.values())
    for item in report.files:
        spaces = {
            _namespace(term.value)
            for quad in item.quads
            for term in (quad.subject, quad.predicate, quad.object)
            if isinstance(term, ox.NamedNode)
        }
        for space in sorted(spaces - set(known)):
            near = difflib.get_close_matches(space, known, n=1, cutoff=0.95)
            if near:
                prefix = next(p for p, namespace in PREFIXES.items() if namespace == near[0])
                click.echo(
                    f"note: {item.source} names things in <{space}>, which cbrs does not know: is it {prefix}:"
                    f" <{near[0]}> mistyped?",
                    err=True,
                )


def _namespace(iri: str) -> str:
    cut = max(iri.rfind("#"), iri.rfind("/"))
    return iri[: cut + 1] if cut > 0 else iri


def _note_defaulted(report: LoadReport) -> None:
    """Name the files that went to graph:services by default though they describe no service: a map
    file loaded without --graph map went there without a word, and its objects were in no map."""
    model = CBRS + "hasOWLSModel"
    for item in report.files:
        if item.graph == GraphName.SERVICES.iri and item.quads and all(q.predicate.value != model for q in item.quads):
            click.echo(
                f"note: {item.source} describes no service and went to graph:services, the default; "
                "the semantic map is --graph map, a task --graph requirements (docs/tasks.md)",
                err=True,
            )


def _added_summary(report: LoadReport) -> list[str]:
    """What the load changed: the lines above count what the files gave, which a reload gives again
    although the store held all of it already and nothing was added."""
    graphs = sorted((graph, n) for graph, n in report.added.items() if n)
    if len(graphs) == 1:
        where = f" into {shorten(graphs[0][0])}"
    else:
        where = "".join(f"{', ' if i else ': '}{n} into {shorten(graph)}" for i, (graph, n) in enumerate(graphs))
    lines = [f"added {_plural(report.added_quads, 'triple')}{where}; {report.already_present} already present"]
    if not report.already_present:
        return lines
    for items, kind in ((report.files, "file"), (report.imports, "imported ontology")):
        unchanged = [item.source for item in items if item.added_triples == 0]
        if unchanged:
            count = _plural(len(unchanged), kind).replace("ontologys", "ontologies")
            lines.append(f"  all already present, nothing added: {count}{_few(unchanged)}")
    partly = [item for item in (*report.files, *report.imports) if 0 < (item.added_triples or 0) < item.triples]
    for item in partly[:_PARTLY_SHOWN]:
        lines.append(
            f"  {item.source}: added {item.added_triples} of {item.triples} triples, "
            f"{item.triples - (item.added_triples or 0)} already present"
        )
    if len(partly) > _PARTLY_SHOWN:
        lines.append(f"  ... and {len(partly) - _PARTLY_SHOWN} more files with some triples already present")
    return lines


_PARTLY_SHOWN = 20


def _plural(count: int, word: str) -> str:
    return f"{count} {word}" if count == 1 else f"{count} {word}s"


def _loaded_what(item: ParsedFile) -> str:
    if item.owls is None:
        return ""
    services = item.owls.services
    kind = services[0].role if services else "service description"
    counts = [
        _plural(sum(s.inputs for s in services), "input"),
        _plural(sum(s.outputs for s in services), "output"),
        _plural(sum(s.preconditions for s in services), "precondition"),
        _plural(sum(s.effects for s in services), "effect"),
    ]
    text_only = sum(s.text_only for s in services)
    if text_only:
        counts.append(f"{_plural(text_only, 'condition')} as text only")
    return f"{_plural(len(services), kind)} ({', '.join(counts)}), "


def _mended(item: ParsedFile) -> str:
    return f" (mended: {'; '.join(item.repairs)})" if item.repairs else ""


def _load_summary(report: LoadReport, store: Any = None) -> list[str]:
    """The end of a load's output: imported ontologies, then what could not be resolved."""
    lines = []
    owls = [item for item in report.files if item.owls is not None]
    if report.catalogue is not None:
        triples = sum(item.triples for item in report.imports)
        count = len(report.imports)
        lines.append(
            f"imported {count} {'ontology' if count == 1 else 'ontologies'} ({triples} triples) "
            f"into {shorten(GraphName.ONTOLOGY.iri)}"
        )
        for item in report.imports:
            if item.repairs:
                unchanged = ", nothing added (all already present)" if item.added_triples == 0 else ""
                lines.append(f"  {item.source}{_mended(item)}{unchanged}")
        unresolved = sorted({u.iri for u in report.unresolved_imports})
        lines.append(f"unresolved imports: {len(unresolved)}{_few(unresolved)}")
    else:  # an ontology's imports as an OWL-S file's: a Protégé file importing its neighbour was loaded silently
        imports = sorted(
            {
                q.object.value
                for item in report.files
                for q in item.quads
                if q.predicate.value == OWL_IMPORTS and isinstance(q.object, ox.NamedNode)
            }
        )
        if imports:
            lines.append(f"imports not followed (no --catalog): {len(imports)}{_few(imports)}")
            held = [iri for iri in imports if store is not None and holds_ontology(store, iri)]
            if held:  # "not followed" alone reads as missing after a reload
                lines.append(f"  of which already in the store: {len(held)}{_few(held)}")
    if owls:  # only an OWL-S file's concepts are looked up
        for used_as in ("parameter type", "statement term"):
            concepts = sorted({u.iri for u in report.unresolved_concepts if u.used_as == used_as})
            lines.append(f"unresolved {used_as}s (declared by no loaded ontology): {len(concepts)}{_few(concepts)}")
    if owls:
        notes = [note for item in owls if item.owls for note in item.owls.notes]
        if notes:
            more = f" and {len(notes) - 1} more" if len(notes) > 1 else ""
            lines.append(f"conversion notes: {notes[0]}{more}")
        expressions = sum(item.owls.expressions for item in owls if item.owls)
        turned = sum(item.owls.expressions_turned for item in owls if item.owls)
        if expressions:
            lines.append(
                f"preconditions and effects: {expressions} expressions, {turned} made statements, "
                f"{expressions - turned} kept as text only"
            )
    return lines


OWL_IMPORTS = OWL + "imports"


def _few(iris: list[str], limit: int = 3) -> str:
    """The first IRIs of a list of what a load could not find: whole but for a declared prefix, as where
    to look for it (a derived prefix, ``ontology:books.owl``, would hide the host)."""
    if not iris:
        return ""
    with store_names(None):
        shown = ", ".join(shorten(i) for i in iris[:limit])
    return f" ({shown}{', ...' if len(iris) > limit else ''})"


@cli.command()
@click.argument("text", required=False)
@click.option("--file", "query_file", type=click.File("r", encoding="utf-8"), help="Read the query from a .rq file.")
@click.option("--name", metavar="NAME", help="Run the named query queries/NAME.rq (see --list).")
@click.option("--bind", "bindings", multiple=True, metavar="VAR=VALUE", help="Bind a named query's parameter.")
@click.option(
    "--format",
    "fmt",
    type=click.Choice(RESULT_FORMATS),
    help="Output format [env CBRS_FORMAT; default table].",
)
@click.option("--list", "list_queries", is_flag=True, help="List the named queries and their parameters.")
@pass_app
def query(
    app: App,
    text: str | None,
    query_file: Any,
    name: str | None,
    bindings: tuple[str, ...],
    fmt: str | None,
    list_queries: bool,
) -> None:
    """Run a SPARQL query given as TEXT, from --file, or by --name with --bind values."""
    fmt = setting("format").resolve(fmt)
    if fmt not in RESULT_FORMATS:
        raise click.BadParameter(f"{fmt!r} is not one of {', '.join(RESULT_FORMATS)}", param_hint="CBRS_FORMAT")
    if list_queries:
        _list_queries(app, fmt)
        return
    sources = [s for s in (text, query_file, name) if s]
    if len(sources) != 1:
        raise click.UsageError("give exactly one of TEXT, --file or --name")
    values = _bindings(bindings)
    result: QueryResult | IsolatedResult
    if name:
        _check_required(app.kb, name, values)
        # --bind takes the names the browser shows (books1:Novel), and its notes print them; the rows,
        # printed after, keep the declared prefixes, as the endpoint's do
        with store_names(StoreNames(lambda: app.kb)):
            result = app.kb.run(name, values)
            _note_unknown_bindings(app.kb, name, values)
    else:
        if values:
            raise click.UsageError("--bind works with --name, whose parameters are declared")
        body = (text if text else query_file.read()).removeprefix("\ufeff")  # a byte order mark the parser refuses
        update = _UPDATE_START.match(body)
        if update:
            raise click.ClickException(
                f"this is a SPARQL update ({update.group(1).upper()}); cbrs query runs queries only: "
                "run it with cbrs update (or send it to /update of cbrs serve, with its update token)"
            )
        # the names cbrs prints for this store (lab4:Trolley1) may be written: their derived prefixes are
        # declared above the text when it uses them and declares them not (from the store's IRIs only)
        names = StoreNames(lambda: app.kb)
        added = store_prefixes_used(body, lambda: names.prefixes)
        try:
            result = _evaluate(app.kb, declared(added, body))
        except QuerySyntaxError as error:  # a prefix nobody declared: said plainly, as the endpoint does
            parsed = unexplained(error)  # the store explained the text run, prologue and all: explained anew
            counted = one_line_up(parsed, body) if added else parsed
            explained = explain_syntax_error(counted, body, "query", names.prefixes)
            if explained is error:
                raise
            raise explained from error
        with store_names(names):  # a misspelt term matches nothing, and "(0 rows)" said no more
            for note in unmentioned_names(app.kb, body, added):
                click.echo(f"note: {note}", err=True)
    click.echo(render_result(result, fmt))  # a list: a graph a query worker answered (_evaluate)


def _evaluate(kb: KnowledgeBase, text: str) -> QueryResult | IsolatedResult:
    """A user's query text evaluated where a crash of the SPARQL engine costs a child process only when it
    sorts (cbrs.isolated_queries: ORDER BY over dateTimes with and without a time zone aborts Oxigraph);
    in this process otherwise, and always on a remote store, which evaluates on its own server."""
    result: QueryResult | IsolatedResult
    if not isinstance(kb.store, EmbeddedStore) or not sorts(text):
        result = kb.query(text)
    else:
        with IsolatedQueries(kb.store) as isolated:
            result = isolated.query(text)
    if (first_keyword(text) or "").upper() == "DESCRIBE" and isinstance(result, ox.QueryTriples | list):
        return complete(result, about_in(kb.store))  # through skolemised blank nodes, as the endpoint's
    return result


def _check_required(kb: KnowledgeBase, name: str, values: dict[str, str]) -> None:
    """Refuse a named query whose required parameter is not bound, saying the --bind that binds it (the
    library's "binding description: ... needs this parameter" did not say how)."""
    for parameter in kb.queries.get(name).parameters.values():
        if parameter.required and parameter.name not in values:
            what = f" ({parameter.description})" if parameter.description else ""
            raise click.ClickException(
                f"query {name!r} needs --bind {parameter.name}={parameter.kind.upper()}{what};"
                " cbrs query --list shows each query's parameters"
            )


def _note_unknown_bindings(kb: KnowledgeBase, name: str, values: dict[str, str]) -> None:
    """Say on standard error which bound IRIs the store mentions nowhere: a misspelt class or prefix
    (``kind=cbrs:DynamicPerceptonComponent``) gave "(0 rows)" and no word of why
    (:func:`cbrs.unmentioned_names.unmentioned_bindings`, which a program calls too)."""
    for note in unmentioned_bindings(kb, name, values):
        click.echo(f"note: {note}", err=True)


# An update, after its prologue (PREFIX and BASE declarations, comments): the query parser's own
# message for one ("expected CONSTRUCT") does not say what is wrong.
_UPDATE_START = re.compile(
    r"(?:\s|#[^\n]*(?=\n|\Z)|PREFIX\s*[\w.-]*:\s*<[^>]*>|BASE\s*<[^>]*>)*"
    r"(INSERT|DELETE|LOAD|CLEAR|DROP|CREATE|ADD|MOVE|COPY|WITH)\b",
    re.IGNORECASE,
)


@cli.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--update",
    is_flag=True,
    help="Bring the store in line with the FILES: replace the descriptions of their advertisements already "
    "registered and register the others (one transaction). An OWL-S file is converted as cbrs load "
    "converts it, and replaces what an earlier load of it gave.",
)
@click.option("--json", "as_json", is_flag=True, help='Print {"registered": [IRI...], "updated": [IRI...]} as JSON.')
@pass_app
def register(app: App, files: tuple[Path, ...], update: bool, as_json: bool) -> None:
    """Register the advertisements in Turtle FILES (or RDF/XML, JSON-LD, N-Triples; all checked first; one
    transaction: a bad file registers none of them)."""
    inputs = [(file.read_bytes(), str(file)) for file in files]
    if update:
        with _undeclared_prefixes():
            synced = app.kb.registry.synced_all(inputs)
        registered = [iri for done in synced for iri in done.registered]
        updated = [iri for done in synced for iri in done.updated]
        if as_json:
            click.echo(json.dumps({"registered": sorted(registered), "updated": sorted(updated)}, indent=2))
            return
        for iri in sorted(registered + updated):
            click.echo(f"{'registered' if iri in registered else 'updated'} {shorten(iri)}")
        for done in synced:
            if done.conversion is not None:  # an OWL-S file: what cbrs load of it says besides its counts
                for item in done.conversion.files:
                    if item.repairs:
                        click.echo(f"read {item.source}{_mended(item)}")
                for line in _load_summary(done.conversion, app.kb.store):
                    click.echo(line)
        return
    try:
        with _undeclared_prefixes():
            iris = app.kb.registry.register_all(inputs)
    except AlreadyRegisteredError as error:  # some of the files' may be registered, some not: --update does both
        again = " ".join(shlex.quote(str(file)) for file in files)
        raise click.ClickException(f"{error}: cbrs register --update {again}") from error
    if as_json:
        click.echo(json.dumps({"registered": list(iris), "updated": []}, indent=2))
        return
    for iri in iris:
        click.echo(f"registered {shorten(iri)}")


@cli.command()
@click.argument("iri")
@click.option("--json", "as_json", is_flag=True, help='Print {"deregistered": IRI, "triples": N} as JSON.')
@pass_app
def deregister(app: App, iri: str, as_json: bool) -> None:
    """Remove a registered advertisement, or a requirement, and the nodes of its description (one transaction)."""
    full = _resource_iri(app.kb, iri)
    name = shorten(full)  # as it was named: its prefix may be the store's own, gone with it
    try:
        removed = app.kb.registry.deregister(full)
    except KnowledgeBaseError as error:
        hint = not_found_hint(app.kb, full) if type(error) is NotFoundError else _prefix_hint(full)
        raise click.ClickException(f"{error}{hint}") from error
    if full in app.kb.liveness.states():  # a live component: not listed as available until its next heartbeat
        app.kb.liveness.forget(full)
    if as_json:
        click.echo(json.dumps({"deregistered": full, "triples": removed}, indent=2))
        return
    click.echo(f"deregistered {name} ({removed} triples)")


@cli.command()
@click.option("--json", "as_json", is_flag=True, help="Print the advertisements as JSON (lists whole).")
@click.option("--full", is_flag=True, help="Print every list whole, however wide the lines.")
@click.option(
    "--width",
    type=click.IntRange(min=0),
    help="Cut the lists to lines of this many columns (0: whole). Default: on a terminal its width "
    "(COLUMNS if set); to a pipe or a file, whole lines.",
)
@pass_app
def services(app: App, as_json: bool, full: bool, width: int | None) -> None:
    """List the registered advertisements with their kind, device and inputs -> outputs (each list in IRI
    order), and whether a component registered live (in another process) can be invoked now.

    On a terminal each list is cut to its width with the count of the names left out ("home:A +3 more");
    when the other columns leave the lists too little room, each row takes two lines: the service, then,
    indented, the rest. Names are not cut unless one alone is too wide ("http://127.0.0.1/…#Car"). A pipe
    or a file gets whole lines, one a row, as do --full and --width 0; --json is never cut."""
    rows = sorted_lists(app.kb.select("advertisements"), ("inputs", "outputs"))  # the store's order varies
    live = app.kb.liveness.states()
    if as_json:
        found = []
        for row in rows:
            item = json_row(row, ("inputs", "outputs"))
            state = live.get(row["service"].value)
            if state is not None:
                item["live"] = {"available": state.live, "reason": state.reason}
            found.append(item)
        click.echo(json.dumps(found, indent=2))
        return
    body: list[list[Cell]] = []
    for row in rows:
        cells: list[Cell] = [
            term_text(row["service"]),
            term_text(row.get("kind")).replace("cbrs:", "").replace("Component", ""),
            term_text(row.get("deviceName")),
            term_text(row.get("inputs")).split(),
            term_text(row.get("outputs")).split(),
        ]
        body.append(cells + ([_live_state(live.get(row["service"].value))] if live else []))
    limit = None if full else output_width(width)
    headers = ["service", "kind", "device", "inputs", "outputs"] + (["live"] if live else [])
    text, cut = fitted_table(headers, body, limit)
    click.echo(text)
    gone = sum(1 for row in rows if row["service"].value in live and not live[row["service"].value].live)
    notes = [f"{len(rows)} advertisements"]
    if gone:
        notes.append(f"{gone} live component(s) unavailable now")
    if cut:
        notes.append(f"{cut} list{'s' if cut != 1 else ''} cut to {limit} columns: --full prints them whole")
    click.echo(f"({'; '.join(notes)})")


def _live_state(state: ComponentState | None) -> str:
    """'-' for a component not registered live; else available, or unavailable and why."""
    if state is None:
        return "-"
    return "available" if state.live else f"unavailable: {state.reason or 'no reason recorded'}"


@cli.command()
@click.argument("iri")
@click.option("--json", "as_json", is_flag=True, help="Print as JSON.")
@pass_app
def show(app: App, iri: str, as_json: bool) -> None:
    """Show a service description's six-tuple, or any resource's triples (IRI or prefix:name)."""
    full = _resource_iri(app.kb, iri)
    kb = app.kb
    if not kb.describes(full):
        raise click.ClickException(f"nothing in the store mentions <{full}>{not_found_hint(kb, full)}")
    is_description = bool(kb.select("description", {"description": full}))
    if is_description:
        description = kb.description(full)
        if as_json:
            click.echo(json.dumps(description.to_dict(), indent=2))
        else:
            click.echo(_describe(description))
        return
    rows = sorted(kb.select("resource_triples", {"resource": full}), key=_triple_order)
    names = _NodeNames(kb)
    own = names.view(ox.NamedNode(full))
    views = [names.view(row["other"], row["direction"].value) for row in rows]
    if as_json:
        found = []
        for row, view in zip(rows, views, strict=True):
            item: dict[str, Any] = {k: v.value for k, v in row.items() if k != "resource"}
            if view is not None:
                item["other_text"] = view["text"]
                item.update({key: view[key] for key in ("expression", "owner") if key in view})
            found.append(item)
        click.echo(json.dumps(found, indent=2))
        return
    click.echo(f"{shorten(full)}")
    if own is not None:
        click.echo(f"  = {own['text']}")
    body = [
        [
            term_text(r["direction"]),
            term_text(r["predicate"]),
            view["text"] if view is not None else term_text(r["other"]),
            term_text(r["graph"]),
        ]
        for r, view in zip(rows, views, strict=True)
    ]
    click.echo(table(["direction", "predicate", "value", "graph"], body))
    if names.left == 0 and any(is_skolem(r["other"]) and view is None for r, view in zip(rows, views, strict=True)):
        click.echo(f"(the first {REMOTE_NAMED_NODES} anonymous nodes named; on a remote store each costs requests)")


def _triple_order(row: dict[str, ox.NamedNode | ox.BlankNode | ox.Literal]) -> tuple[bool, str, int, str]:
    """A resource's triples as ``show`` lists them: out before in, then by predicate, then by the other term
    (blank nodes, IRIs, literals, as SPARQL orders them)."""
    other = row["other"]
    kind = 0 if isinstance(other, ox.BlankNode) else 1 if isinstance(other, ox.NamedNode) else 2
    return row["direction"].value != "out", row["predicate"].value, kind, other.value


REMOTE_NAMED_NODES = 200
"""How many anonymous nodes ``show`` names on a remote store, where each costs a few requests (the 195
parameters pointing at cbrs:Parameter in the bundled store took 1.1 s); the rest keep their skolem IRIs."""


class _NodeNames:
    """Names the skolemised nodes of one ``show`` (``cbrs.output.node_view``) from the stored triples,
    those graph:entailed derives left out; each node's triples are read once."""

    def __init__(self, kb: KnowledgeBase) -> None:
        self.store = kb.store
        self.left = None if isinstance(kb.store, EmbeddedStore) else REMOTE_NAMED_NODES
        self._out: dict[ox.NamedNode, list[ox.Quad]] = {}
        self._into: dict[ox.NamedNode, list[ox.Quad]] = {}

    def out(self, node: ox.NamedNode) -> list[ox.Quad]:
        if node not in self._out:
            self._out[node] = list(self.store.quads(node))
        return self._out[node]

    def into(self, node: ox.NamedNode) -> list[ox.Quad]:
        if node not in self._into:
            entailed = GraphName.ENTAILED.node
            self._into[node] = [q for q in self.store.quads(None, None, node) if q.graph_name != entailed]
        return self._into[node]

    def view(self, term: Term, direction: str = "out") -> dict[str, Any] | None:
        if not is_skolem(term) or self.left == 0:
            return None
        if self.left is not None:
            self.left -= 1
        return node_view(self.out, self.into, term, direction)


@cli.command("check")
@click.option(
    "--graph",
    "graphs",
    multiple=True,
    metavar="NAME|IRI",
    help="A graph to reason over (repeatable): " + ", ".join(g.value for g in GraphName) + ", or the IRI of "
    "a graph of your own (cbrs load --graph IRI; add --graph ontology to check it with cbrs's ontologies). "
    "Default: ontology, services and requirements.",
)
@click.option(
    "--write-inferred",
    is_flag=True,
    help="Also write what HermiT concludes and the store does not already say (inferred subclasses, "
    "equivalences, types of individuals) to graph:inferred, replacing what it held; refused, nothing "
    "written, when the graphs are inconsistent or have an unsatisfiable class (docs/ontologies.md).",
)
@click.option(
    "--timeout",
    type=click.FloatRange(min=0, min_open=True),
    metavar="SECONDS",
    help="Seconds HermiT may take before its process is stopped and the check fails saying so. Default: the "
    f"check_timeout setting ({setting('check_timeout').env}, {setting('check_timeout').default():g} s; "
    "docs/ontologies.md, 'How long HermiT may take').",
)
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@pass_app
def check_command(
    app: App, graphs: tuple[str, ...], write_inferred: bool, timeout: float | None, as_json: bool
) -> None:
    """Run the HermiT OWL reasoner (owlready2; needs Java) over the ontologies and registered descriptions.

    Reports whether they are consistent and which classes are unsatisfiable; exits with status 1 if either.
    With --write-inferred, HermiT's new conclusions go into graph:inferred, where SPARQL sees them.
    HermiT has --timeout seconds (or the check_timeout setting's) before it is stopped.
    """
    from cbrs import check as checking  # owlready2 loads only for this command

    chosen = graphs or checking.DEFAULT_GRAPHS
    try:
        if write_inferred:
            result, inferred = checking.write_inferred(app.kb, chosen, timeout)
        else:
            result, inferred = checking.check(app.kb, chosen, timeout), None
    except checking.ReasonerTimeoutError as error:  # its words name the setting; this run may take --timeout
        error.add_note("or give this check longer: cbrs check --timeout SECONDS")
        raise
    except (UnknownGraphError, checking.NoSuchGraphError) as error:  # --graph graph:mapp: which it may mean
        _note_near_graphs(error, graphs, app.kb.store.graphs(), own_count=True)
        raise
    if as_json:
        answer = result.to_dict()
        if inferred is not None:
            answer["inferred"] = inferred.to_dict()
        click.echo(json.dumps(answer, indent=2))
    else:
        click.echo(_check_text(result))
        if inferred is not None:
            click.echo(_inferred_text(inferred))
    if not result.ok:
        raise SystemExit(1)


def _note_near_graphs(error: Exception, given: Iterable[str], held: Collection[str], own_count: bool = False) -> None:
    """Add to ``error`` (a --graph that names no graph) the graphs it may mean (:func:`cbrs.graph_names.graph_hint`)."""
    hint = graph_hint(given, held, own_count, prefixed=False)  # check and load read no graph:NAME
    if hint is not None:
        error.add_note(hint)


def _inferred_text(inferred: Any) -> str:
    change = f"{inferred.added} added, {inferred.removed} removed" if inferred.changed else "unchanged"
    return (
        f"{shorten(inferred.graph)}: {inferred.holds} conclusions ({change}; "
        f"{inferred.already_said} already stated or entailed, left out)"
    )


def _check_text(result: Any) -> str:
    where = f"{', '.join(shorten(g) for g in result.graphs)} ({result.triples} triples)"
    if not result.consistent:
        verdict = "INCONSISTENT"
    elif result.unsatisfiable:
        count = len(result.unsatisfiable)
        verdict = f"consistent, {count} unsatisfiable class{'es' if count > 1 else ''}"
    else:
        verdict = "consistent, no unsatisfiable class"
    lines = [f"{result.reasoner} over {where}: {verdict} ({result.seconds:.1f} s)"]
    lines += [f"  unsatisfiable: {shorten(iri)}" for iri in result.unsatisfiable]
    if result.range_clashes:
        lines.append("Literals whose datatype is not their property's declared range (places to look first):")
        lines += [f"  {clash.text()}" for clash in result.range_clashes[:20]]
        if len(result.range_clashes) > 20:
            lines.append(f"  ... and {len(result.range_clashes) - 20} more (--json lists them all)")
    return "\n".join(lines)


@cli.command("settings")
@click.option(
    "--json", "as_json", is_flag=True, help="Print the settings as JSON (the update token only as set or not)."
)
def settings_command(as_json: bool) -> None:
    """List the settings, their environment variables and current values."""
    if as_json:
        listed = [
            {"setting": s.name, "environment": s.env, "value": s.plain(s.resolve()), "help": s.help} for s in SETTINGS
        ]
        click.echo(json.dumps(listed, indent=2))
        return
    body = [[s.name, s.env, s.shown(s.resolve()), s.help] for s in SETTINGS]
    click.echo(table(["setting", "environment", "value", "help"], body))


@cli.command()
@click.option(
    "--external",
    is_flag=True,
    help="Run the ceiling cameras as programs of their own that register over the bridge, kill one "
    "mid-run with SIGKILL, and finish FetchMyPen on the other (docs/components.md).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="World seed of the external demo's run.")
@pass_app
def demo(app: App, external: bool, seed: int) -> None:
    """A tour of the knowledge base: what is stored, an advertisement, a requirement, a query, a ranking;
    then the paper's two scenarios planned and run in the simulated home (the [sim] extra), FetchMyPen again
    with a camera failed. 10-20 s."""
    if external:
        _external_demo(seed)
        return
    kb = app.kb
    click.echo(f"cbrs {__version__} -- store: {without_password(kb.store.location)}\n")
    stats = kb.statistics()
    click.echo("Named graphs:")
    for graph in GraphName:
        click.echo(f"  {shorten(graph.iri):<20} {stats.get(graph.iri, 0):>7} triples")
    ads = kb.select("advertisements")
    reqs = kb.select("requirements")
    click.echo(f"\n{len(ads)} advertisements, {len(reqs)} requirements.\n")
    click.echo("Paper Table 1, the ceiling camera's LocateMobileRobot advertisement:")
    click.echo(_describe(kb.description(expand("svc:LocateMobileRobot_CeilingCamera01"))))
    click.echo("\nPaper Table 2, the robot's self-position requirement:")
    click.echo(_describe(kb.description(expand("req:RobotSelfPosition"))))
    click.echo("\nDynamic perception components (cbrs query --name advertisements --bind kind=...):")
    click.echo(render_result(kb.run("advertisements", {"kind": "cbrs:DynamicPerceptionComponent"}), "table"))
    from cbrs.cli_actions import scenario_runs
    from cbrs.cli_reasoner import ranking_text

    click.echo("\nPaper Table 3: the advertisements ranked for the requirement (cbrs match ... --explain):")
    click.echo(ranking_text(kb, expand("req:RobotSelfPosition"), top=4, explain=1))
    click.echo("\nPaper section 6.2: the two scenarios, planned and run in the simulated home (cbrs run TASK):")
    shown = ProgressLine()  # on a terminal only, as cbrs load's: the runs take 10-15 s
    try:
        text, succeeded = scenario_runs(kb, progress=shown)
    finally:
        shown.clear()
    click.echo(text)
    if not succeeded:
        raise SystemExit(1)  # a tour that reports a failed run must not tell a script all went well


def _external_demo(seed: int) -> None:
    require("sim", "cbrs demo --external")
    from cbrs.cli_actions import run_text
    from cbrs.external_demo import run_external_demo

    run = run_external_demo(seed=seed, say=click.echo)
    result = run.result
    if result is None:
        raise SystemExit(1)
    click.echo(run_text(result, 0.0, 0.0).rsplit(";", 1)[0])
    if run.detected_after is not None:
        click.echo(f"the killed camera was noticed after {run.detected_after:.3f} s (lease {run.lease:g} s)")
    if not result.succeeded:
        raise SystemExit(1)


def _describe(d: ServiceDescription) -> str:
    lines = [f"{shorten(d.iri)}  ({', '.join(shorten(t) for t in d.types)})"]
    if d.label:
        lines.append(f"  label        {d.label}")
    lines.append(f"  DN           {d.device_name or '-'}")
    lines.append(f"  SN           {d.service_name or '-'}")
    lines.append(f"  SC           {d.category or '-'}")
    if isinstance(d, Advertisement) and d.device:
        lines.append(f"  device       {shorten(d.device)}")
    if isinstance(d, Requirement):
        if d.requested_by:
            lines.append(f"  requested by {shorten(d.requested_by)}")
        if d.for_task:
            lines.append(f"  for task     {shorten(d.for_task)}")
    for parameter in (*d.inputs, *d.outputs):
        parts = ""
        if parameter.tree and parameter.tree.children:
            parts = "  parts: " + ", ".join(shorten(c.concept) for c in parameter.tree.children)
        name = f" {parameter.name}" if parameter.name else ""
        lines.append(f"  {parameter.direction:<12} {shorten(parameter.type)}{name}{parts}")
    for role, statements in (("precondition", d.preconditions), ("effect", d.effects), ("deletes", d.deletes)):
        for s in statements:
            lines.append(f"  {role:<12} ({shorten(s.subject)}, {shorten(s.predicate)}, {shorten(s.object)})")
    if d.area:
        box = (
            f"  x {d.area.bounds[0]}..{d.area.bounds[1]}, y {d.area.bounds[2]}..{d.area.bounds[3]}"
            if d.area.bounds
            else ""
        )
        lines.append(f"  SEA          {', '.join(shorten(a) for a in d.area.areas) or '-'}{box}")
    for q in d.qos:
        bound = (
            {"lower": " (max)", "higher": " (min)"}.get(q.better_when or "", "") if isinstance(d, Requirement) else ""
        )
        lines.append(f"  QoS          {shorten(q.metric)} = {q.value:g}{bound}")
    return "\n".join(lines)


def _list_queries(app: App, fmt: str) -> None:
    """The named queries as a table, or as JSON when asked (a script listing them got the table)."""
    queries = [app.kb.queries.get(name) for name in app.kb.queries.names()]
    if fmt == "json":
        listed = [
            {"name": q.name, "title": q.title, "parameters": [vars(p) for p in q.parameters.values()]} for q in queries
        ]
        click.echo(json.dumps(listed, indent=2))
        return
    body = []
    for q in queries:
        params = ", ".join(f"{p.name}{'*' if p.required else ''}:{p.kind}" for p in q.parameters.values())
        body.append([q.name, params or "-", q.title])
    click.echo(table(["name", "parameters (* required)", "title"], body))


def _into(item: ParsedFile) -> str:
    """How many triples went into which graph: a TriG or N-Quads file may name graphs of its own."""
    counts = Counter(
        quad.graph_name.value if isinstance(quad.graph_name, ox.NamedNode) else item.graph for quad in item.quads
    )
    if item.bulk is not None or len(counts) <= 1:
        return f"{item.triples} triples into {shorten(item.graph)}"
    parts = ", ".join(f"{n} into {shorten(graph)}" for graph, n in sorted(counts.items()))
    return f"{item.triples} triples: {parts}"


def _resource_iri(kb: KnowledgeBase, text: str) -> str:
    """:func:`parse_iri`, offering for a bare name (LocateMobileRobot_CeilingCamera01) the prefixed names
    the store mentions."""
    try:
        return parse_iri(text)
    except click.BadParameter:
        if ":" in text:
            raise
        known = [f"{prefix}:{text}" for prefix, space in PREFIXES.items() if _mentions(kb, space + text)]
        if not known:
            raise
        raise click.BadParameter(
            f"{text!r} has no prefix; did you mean {' or '.join(known)}?", param_hint="IRI"
        ) from None


def _mentions(kb: KnowledgeBase, iri: str) -> bool:
    try:
        return kb.describes(iri)
    except ValueError:  # not an IRI at all
        return False


def _prefix_hint(full: str) -> str:
    """A hint when ``full`` looks like prefix:name with a prefix nobody declared (lab:Cam for a lab's own);
    the closest prefixes first, the store's derived ones among them (docs/web.md)."""
    scheme, _, local = full.partition(":")
    if is_absolute_iri(full):  # a scheme cbrs reads bare, or one with an authority
        return ""
    near = near_prefixes(scheme)
    meant = f"; did you mean {' or '.join(f'{p}:{local}' for p in near)}?" if near else ""
    return f" (is {scheme!r} a mistyped prefix? known prefixes: {', '.join(PREFIXES)}{meant})"


def not_found_hint(kb: KnowledgeBase, full: str, among: list[str] | None = None) -> str:
    """What to say after "no such resource": the names nearest ``full`` (:func:`cbrs.task_names.near_names`),
    else a hint at a mistyped prefix."""
    from cbrs.task_names import near_names  # imports the action model: only when a name named nothing

    near = near_names(kb, full, among) if "://" in full else []
    return f"; did you mean {' or '.join(near)}?" if near else _prefix_hint(full)


def _bindings(texts: tuple[str, ...]) -> dict[str, str]:
    """The --bind options by parameter; a parameter bound twice is refused: the query takes one value."""
    values: dict[str, str] = {}
    for name, value in map(_split_binding, texts):
        if name in values and values[name] != value:
            raise click.BadParameter(
                f"{name} is bound twice ({values[name]!r} and {value!r}); a named query takes one value for it",
                param_hint="--bind",
            )
        values[name] = value
    return values


def _split_binding(text: str) -> tuple[str, str]:
    name, sep, value = text.partition("=")
    if not sep or not name:
        raise click.BadParameter(f"{text!r} is not VAR=VALUE", param_hint="--bind")
    return name.lstrip("?$"), value


cli.add_command(export)
cli.add_command(restore)
cli.add_command(update)


def main() -> None:
    """Entry point. click reports usage and library errors in one line; anything else is a bug,
    reported in one line too unless CBRS_DEBUG asks for the traceback. A library error raised after the
    command, as its store closes (``ctx.call_on_close``, outside :meth:`_Group.invoke`), is said as the
    others are: ``Error: ...`` and status 1, on standard error only (the command's output is out already)."""
    try:
        cli.main(prog_name="cbrs")
    except KnowledgeBaseError as error:
        click.echo(f"Error: {with_notes(error)}", err=True)
        sys.exit(1)
    except Exception as error:
        if os.environ.get("CBRS_DEBUG"):
            traceback.print_exc()
        click.echo(f"internal error: {type(error).__name__}: {error} (set CBRS_DEBUG=1 for the traceback)", err=True)
        sys.exit(2)
