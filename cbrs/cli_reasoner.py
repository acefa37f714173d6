"""``cbrs match`` and ``cbrs eval``: thin commands over the reasoner package."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import click

from cbrs.app import App, parse_iri, pass_app
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import NotFoundError
from cbrs.kb.namespaces import shorten
from cbrs.output import ProgressLine, table
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Candidate, Matchmaker, MatchResult, MatchStatus
from cbrs.reasoner.methods import METHODS
from cbrs.settings import setting


def match_config(params: tuple[str, ...], base: MatchConfig | None = None) -> MatchConfig:
    """``base`` (MatchConfig's defaults) with the ``--param`` options, else the match_params setting; says
    on standard error which are set, so that no figure is read as the defaults' by mistake."""
    try:
        given = setting("match_params").resolve(setting("match_params").from_options(params))
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="--param") from None
    if given:
        click.echo(f"matchmaking parameters: {', '.join(given)}", err=True)
    return (base or MatchConfig()).with_params(given)


def _list_params(as_json: bool) -> None:
    """``--params``: every matchmaking parameter with its default; as JSON with ``--json`` (it printed the
    table, which a script asking for JSON cannot read)."""
    defaults = MatchConfig()
    if as_json:
        click.echo(json.dumps({name: getattr(defaults, name) for name in MatchConfig.parameter_names()}, indent=2))
        return
    rows = [[name, repr(getattr(defaults, name))] for name in MatchConfig.parameter_names()]
    click.echo(table(["parameter", "default"], rows))
    click.echo("(docs/matchmaking.md section 9.1 says what each does; set them with --param NAME=VALUE)")


_PARAM = click.option(
    "--param",
    "params",
    multiple=True,
    metavar="NAME=VALUE",
    help="Set a matchmaking parameter (repeatable; cbrs match --params lists them), instead of the match_params "
    f"setting [env {setting('match_params').env}].",
)


@click.command()
@click.argument("requirement", required=False)  # not with --params; checked below
@click.option("--top", default=10, show_default=True, type=click.IntRange(min=1), help="How many candidates to show.")
@click.option("--method", type=click.Choice(METHODS), default="sem-str", show_default=True, help="Matching method.")
@click.option("--explain", is_flag=True, help="Show, for each shown candidate, the entity pairs and what it lacks.")
@click.option("--json", "as_json", is_flag=True, help="Print the ranking (with explanations) as JSON.")
@_PARAM
@click.option(
    "--params",
    "list_params",
    is_flag=True,
    help="List the matchmaking parameters and their defaults (as JSON with --json), then exit.",
)
@pass_app
def match(
    app: App,
    requirement: str | None,
    top: int,
    method: str,
    explain: bool,
    as_json: bool,
    params: tuple[str, ...],
    list_params: bool,
) -> None:
    """Rank the advertisements against REQUIREMENT: an IRI, prefix:name, or a bare name in req: (RobotSelfPosition)."""
    if list_params:
        _list_params(as_json)
        return
    if requirement is None:
        raise click.MissingParameter(param_type="argument", param_hint="'REQUIREMENT'")
    config = match_config(params)
    iri = parse_iri(requirement, "REQUIREMENT", default_prefix="req")  # a bare name, as /cbrs/match takes it
    try:
        if as_json:
            result = Matchmaker(app.kb, method, config).rank(iri, explain=top)
            click.echo(json.dumps(result.to_dict(top), indent=2))
            return
        click.echo(ranking_text(app.kb, iri, top, top if explain else 0, method, config))
    except NotFoundError as error:  # a mistyped requirement: the nearest stored ones
        if error.iri != iri:
            raise
        from cbrs.cli import not_found_hint

        stored = [row["requirement"].value for row in app.kb.select("requirements")]
        raise click.ClickException(f"{error}{not_found_hint(app.kb, iri, stored)}") from error


def ranking_text(
    kb: KnowledgeBase,
    requirement: str,
    top: int,
    explain: int,
    method: str = "sem-str",
    config: MatchConfig | None = None,
) -> str:
    """The ranking table for ``requirement`` and the explanations of its first ``explain`` candidates."""
    result = Matchmaker(kb, method, config).rank(requirement, explain=top)
    parts = [_ranking(result, top)]
    for position, candidate in enumerate(result.candidates[:explain], start=1):
        parts.append("\n" + _explanation(position, candidate))
    return "\n".join(parts)


def _ranking(result: MatchResult, top: int) -> str:
    name = shorten(result.requirement)
    if result.status is MatchStatus.MATCHED:
        head = f"{name}: matched by {result.method}; best {shorten(result.candidates[0].advertisement)}"
    else:
        head = f"{name}: no acceptable match by {result.method} (--explain says what each lacks)"
    rows = []
    for position, c in enumerate(result.candidates[:top], start=1):
        parts = " ".join(f"{name[:3]}={value:.2f}" for name, value in c.parts.items())
        verdict = "yes" if c.acceptable else ("; ".join(c.rejected_by) if c.rejected_by else "score too low")
        rows.append([str(position), shorten(c.advertisement), f"{c.score:.3f}", parts, verdict])
    shown = min(top, len(result.candidates))
    return (
        f"{head}\n"
        + table(["#", "advertisement", "score", "parts", "acceptable"], rows)
        + (f"\n({shown} of {len(result.candidates)} advertisements)")
    )


def _explanation(position: int, c: Candidate) -> str:
    lines = [f"#{position} {shorten(c.advertisement)}  score {c.score:.3f}"]
    rows = [
        [
            p.role,
            shorten(p.requested),
            shorten(p.advertised) if p.advertised else "-",
            f"{p.similarity:.2f}",
            p.shown_degree(),
            p.how,
        ]
        for p in c.pairs
    ]
    lines.append(table(["role", "requested", "advertised", "sim", "degree", "how"], rows))
    for lack in c.lacks:
        lines.append(f"  lacks: {lack}")
    for reason in c.rejected_by:
        lines.append(f"  rejected: {reason}")
    return "\n".join(lines)


@click.group("eval")
def eval_group() -> None:
    """Evaluate the matching methods on a test collection."""


@eval_group.command("paper")
@click.option("--method", "methods", multiple=True, type=click.Choice(METHODS), help="Only these methods (repeatable).")
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON.")
@click.option("--plot", type=click.Path(dir_okay=False, path_type=Path), help="Write a bar chart of the figures (PNG).")
@_PARAM
def eval_paper(methods: tuple[str, ...], as_json: bool, plot: Path | None, params: tuple[str, ...]) -> None:
    """The paper-style testbed: 20 requirements against 100 components (reasoner/data/)."""
    from cbrs.reasoner.evaluation import evaluate_paper, plot_report

    config = match_config(params)
    if not as_json:  # several seconds of ranking: say what is going on, as eval owls-tc does
        click.echo(
            f"ranking the testbed's components for each requirement with {', '.join(methods or METHODS)} ...", err=True
        )
    report = evaluate_paper(methods or METHODS, config=config)
    if as_json:
        click.echo(json.dumps(report.to_json(), indent=2))
    else:
        click.echo(report.text())
    if plot is not None:
        click.echo(f"chart written to {plot_report(report, plot)}", err=as_json)


_TEXT_WEIGHT = click.option(
    "--text-weight",
    type=click.FloatRange(0.0, 1.0),
    default=MatchConfig.text_weight,
    show_default=True,
    help="The share of the text similarity in sem-str-text's ranking score.",
)


def _text_weight_first(params: tuple[str, ...], text_weight: float) -> MatchConfig:
    """The matchmaking parameters with ``--text-weight``: given on the command line, it is used whatever
    the match_params setting says (the setting's text_weight replaced it without a word), and given with
    a ``--param text_weight`` of another value, the two are refused."""
    config = match_config(params, MatchConfig(text_weight=text_weight))
    source = click.get_current_context().get_parameter_source("text_weight")
    if source is not click.core.ParameterSource.COMMANDLINE or config.text_weight == text_weight:
        return config
    if params:  # --param replaces the setting: the other value is the command line's own
        raise click.UsageError(
            f"--text-weight {text_weight:g} and --param text_weight={config.text_weight:g} set the same "
            "parameter to two values: give one"
        )
    env = setting("match_params").env
    click.echo(f"--text-weight {text_weight:g} is used, not the text_weight={config.text_weight:g} of {env}", err=True)
    return replace(config, text_weight=text_weight)


@eval_group.command("owls-tc")
@click.argument("folder", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--method", "methods", multiple=True, type=click.Choice(METHODS), help="Only these methods (repeatable).")
@click.option("--json", "as_json", is_flag=True, help="Print the figures as JSON.")
@click.option("--plot", type=click.Path(dir_okay=False, path_type=Path), help="Write precision-recall curves (PNG).")
@_TEXT_WEIGHT
@_PARAM
def eval_owls_tc(
    folder: Path,
    methods: tuple[str, ...],
    as_json: bool,
    plot: Path | None,
    text_weight: float,
    params: tuple[str, ...],
) -> None:
    """An OWL-S test collection in the OWLS-TC layout: services/, ontology/, queries/, relevance.xml."""
    from cbrs.reasoner.owlstc import evaluate_collection, plot_curves

    config = _text_weight_first(params, text_weight)
    if not as_json:
        click.echo(f"loading {folder} and ranking every service for every query ...", err=True)
    shown = ProgressLine()  # on a terminal only: the --json output is as it was
    try:
        report = evaluate_collection(folder, methods or METHODS, config, shown)
    finally:
        shown.clear()
    click.echo(json.dumps(report.to_json(), indent=2) if as_json else report.text())
    if plot is not None:
        click.echo(f"chart written to {plot_curves(report, plot)}", err=as_json)
