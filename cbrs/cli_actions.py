"""``cbrs plan``: a thin command over the composer."""

from __future__ import annotations

import json
from pathlib import Path

import click

from actions.composer import ComposeConfig, Composer, CompositionResult, Objective, PlanStatus, store_plan
from actions.plan import Binding, Plan
from cbrs.app import App, pass_app
from cbrs.output import table
from kb.namespaces import shorten


@click.command()
@click.argument("task")
@click.option("--json", "as_json", is_flag=True, help="Print the plan (or what is unsatisfied) as JSON.")
@click.option(
    "--draw",
    "drawing",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Draw the service resource graph and the plan to FILE.svg or FILE.png.",
)
@click.option(
    "--objective",
    type=click.Choice([o.value for o in Objective]),
    default=Objective.SIMILARITY.value,
    show_default=True,
    help="Choose providers by highest similarity (cost breaks ties) or by lowest cost.",
)
@click.option("--no-store", is_flag=True, help="Do not record the plan in the plans graph.")
@pass_app
def plan(app: App, task: str, as_json: bool, drawing: Path | None, objective: str, no_store: bool) -> None:
    """Compose a plan for TASK: a requirement or action (req:FetchMyPen, act:RobotArmServeACup, or a bare name).

    Exits with status 1 when no plan exists, after saying which need no component meets.
    """
    if drawing is not None and drawing.suffix.lower() not in (".svg", ".png"):
        raise click.BadParameter(f"{drawing.name!r} must end in .svg or .png", param_hint="--draw")
    composer = Composer(app.kb, ComposeConfig(objective=Objective(objective)))
    result = composer.compose(task)
    if result.plan is not None and not no_store:
        store_plan(app.kb, result.plan)
    if drawing is not None:
        from actions.draw import draw  # matplotlib is slow to import; only when asked

        draw(result, drawing)
    click.echo(json.dumps(result.to_dict(), indent=2) if as_json else plan_text(result))
    if drawing is not None and not as_json:
        click.echo(f"drawing written to {drawing}")
    if result.status is not PlanStatus.PLANNED:
        raise SystemExit(1)


def plan_text(result: CompositionResult) -> str:
    """The plan as a table of steps with their sources, or the unsatisfied needs."""
    name = shorten(result.task)
    if result.plan is None:
        lines = [f"{name}: no plan. What no component provides:"]
        lines += [f"  - {u.text()}" for u in result.unsatisfied]
        return "\n".join(lines)
    plan: Plan = result.plan
    how = (
        "composed directly"
        if plan.method == "direct"
        else "decomposed into " + ", ".join(map(shorten, plan.sub_actions))
    )
    head = (
        f"{name}: planned ({how}), {len(plan.steps)} steps, mean similarity {plan.similarity:.3f}, cost {plan.cost:g} s"
    )
    rows = []
    for step in plan.steps:
        sources = "; ".join(_source(b) for b in step.bindings) or "-"
        alternatives = ", ".join(shorten(a) for a in step.alternatives) or "-"
        rows.append(
            [
                str(step.index),
                shorten(step.component),
                shorten(step.action) if step.action else "-",
                sources,
                alternatives,
            ]
        )
    goals = "\n".join(f"  {_source(g)}" for g in plan.goals)
    columns = ["#", "component", "action", "inputs and preconditions from", "alternatives"]
    return f"{head}\n{table(columns, rows)}\nGoals:\n{goals}"


def _source(binding: Binding) -> str:
    origin = "requirement" if binding.source.step is None else f"#{binding.source.step}"
    name = binding.name if binding.role == "input" else "pre"
    if binding.role == "input":
        return f"{name} <- {origin}.{binding.source.name}"
    return f"{binding.name} <- {origin}"
