"""Draw the service resource graph of a composition (like the paper's Figure 15).

Vertices are laid out left to right by their forward-search level (SRI first, SRO/SRE last; a level with
no vertex drawn takes no column). Blue arrows are edges the forward search used, magenta arcs the edges
the backward search walked, thick black arrows the bindings of the chosen plan. Only the vertices of the
plan, their alternatives and the virtual nodes are drawn; the full graph of a home has thousands of edges.
A vertex is named by its local name, qualified where two drawn components share one
(:mod:`cbrs.actions.shown_names`: OWLS-TC's three ``#_MAP_SERVICE`` were three boxes of one name).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from cbrs.actions.composer import Attempt, CompositionResult
from cbrs.actions.graph import SRE, SRI, SRO, VIRTUAL
from cbrs.actions.shown_names import shown_names, two_lines
from cbrs.kb.owls import local_name

FORMATS = (".svg", ".png")
FORWARD, BACKWARD, PLAN = "#1f77b4", "#d62ad0", "#111111"


def draw(result: CompositionResult, path: str | Path, qualifier: Callable[[str], str] | None = None) -> Path:
    """Write the drawing to ``path`` (SVG or PNG, by its suffix) and return the path. Components that
    share a local name are told apart by ``qualifier`` (:func:`cbrs.actions.shown_names.shown_names`)."""
    target = Path(path)
    if target.suffix.lower() not in FORMATS:
        raise ValueError(f"cannot draw to {target.name!r}: use a file name ending in {' or '.join(FORMATS)}")
    drawn = figure(result, qualifier)
    target.parent.mkdir(parents=True, exist_ok=True)
    drawn.savefig(target)
    plt.close(drawn)
    return target


def figure(result: CompositionResult, qualifier: Callable[[str], str] | None = None) -> Figure:
    """The drawing as a matplotlib figure (closed by the caller). Its size follows what it holds: a
    column is as wide as its longest name, and the titles and legend get room of their own
    (constrained layout), so that no two labels lie on one another.

    The layout is made once, before the arrows are added, and then kept: a figure with a layout engine
    is drawn twice by ``savefig`` (once to lay it out), and the arrows, whose ends matplotlib clips
    curve by curve, were most of each drawing; they change no margin, as they lie within the axes."""
    attempts = [a for a in result.attempts if a.plan is not None] or list(result.attempts[:1])
    names = {iri: two_lines(name) for iri, name in shown_names(drawn_components(result), qualifier).items()}
    names.update({iri: iri for iri in VIRTUAL})
    heights = [_rows(a) for a in attempts]
    columns = max(_columns(attempt) for attempt in attempts)
    width = max(16.0, (columns + 0.4) * (_widest(names.values()) + COLUMN_GAP))
    drawn, axes = plt.subplots(
        len(attempts),
        1,
        figsize=(width, 1.2 + ROW_HEIGHT * sum(heights)),
        squeeze=False,
        height_ratios=heights,
        layout="constrained",
    )
    arrows = [(axis, _draw_attempt(axis, attempt, names)) for axis, attempt in zip(axes[:, 0], attempts, strict=True)]
    drawn.legend(
        handles=[
            Line2D([0], [0], color=FORWARD, lw=1.2, label="forward search (qualified post-service)"),
            Line2D([0], [0], color=BACKWARD, lw=1.2, label="backward search (qualified pre-service / pre-action)"),
            Line2D([0], [0], color=PLAN, lw=2.6, label="chosen plan"),
        ],
        loc="outside lower center",
        ncol=3,
        frameon=False,
    )
    drawn.suptitle(f"Service resource graph for {local_name(result.task)}: {result.status.value}")
    _keep_layout(drawn)
    for axis, pending in arrows:
        for arrow in pending:
            _arrow(axis, *arrow)
    return drawn


def _keep_layout(drawn: Figure) -> None:
    """Lay the figure out now and keep that layout: no layout engine is left for ``savefig`` to run."""
    engine = drawn.get_layout_engine()
    if engine is not None:
        engine.execute(drawn)
    with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        drawn.set_layout_engine(None)


FONT_SIZE = 7.5  # points, of a vertex's name
ROW_HEIGHT = 0.75  # inches a vertex of the busiest column takes
COLUMN_GAP = 0.35  # inches between the widest names of two columns


def drawn_components(result: CompositionResult) -> set[str]:
    """The components the drawing shows: each plan's steps and their alternatives."""
    return {
        iri
        for attempt in result.attempts
        if attempt.plan is not None
        for step in attempt.plan.steps
        for iri in (step.component, *step.alternatives)
    }


def _widest(names: Iterable[str]) -> float:
    """Inches the longest line of a drawn vertex name takes (0.6 em a character, and the box's padding)."""
    lines = [line for name in names for line in name.split("\n")]
    return max((len(line) for line in lines), default=3) * FONT_SIZE * 0.6 / 72 + 0.15


def _columns(attempt: Attempt) -> int:
    """How many columns the drawing has: the forward-search levels its vertices are on, and the goals'."""
    last = max(attempt.trace.levels.values(), default=0) + 1
    drawn = {attempt.trace.levels.get(SRI, last)}
    if attempt.plan is not None:
        drawn |= {attempt.trace.levels.get(c, last) for s in attempt.plan.steps for c in (s.component, *s.alternatives)}
    return len(drawn | {last})


def _rows(attempt: Attempt) -> int:
    """How many vertices share the busiest column of this attempt's drawing (at least 3)."""
    columns: dict[int, int] = {}
    if attempt.plan is not None:
        for iri in {c for s in attempt.plan.steps for c in (s.component, *s.alternatives)}:
            level = attempt.trace.levels.get(iri, 0)
            columns[level] = columns.get(level, 0) + 1
    return max(3, *columns.values()) if columns else 3


Arrow = tuple[tuple[float, float], tuple[float, float], str, float, float]  # start, end, colour, width, rad


def _draw_attempt(axis: Axes, attempt: Attempt, names: dict[str, str]) -> list[Arrow]:
    """Draw the attempt's vertices and title; return its arrows, drawn once the layout is made."""
    trace, plan = attempt.trace, attempt.plan
    shown = {SRI} | {goal for goal in (SRO, SRE) if attempt.graph.needs(goal)}
    plan_edges: set[tuple[str, str]] = set()
    if plan is not None:
        by_index = {s.index: s.component for s in plan.steps}
        for step in plan.steps:
            shown.add(step.component)
            shown.update(step.alternatives)
            for b in step.bindings:
                plan_edges.add((by_index[b.source.step] if b.source.step else SRI, step.component))
        for g in plan.goals:
            goal = SRO if g.role == "input" else SRE
            plan_edges.add((by_index[g.source.step] if g.source.step else SRI, goal))
    last = max(trace.levels.values(), default=0) + 1
    level = {iri: trace.levels.get(iri, last) for iri in shown}
    level[SRO] = level[SRE] = last
    columns: dict[int, list[str]] = {}
    for iri in sorted(shown, key=lambda i: (level[i], names[i], i)):
        columns.setdefault(level[iri], []).append(iri)
    position = {}
    for column, (_, members) in enumerate(sorted(columns.items())):  # levels no vertex shown is on take no room
        for row, iri in enumerate(members):
            position[iri] = (float(column), (len(members) - 1) / 2 - row)
    arrows: list[Arrow] = []
    for edges, colour, rad in ((trace.forward, FORWARD, 0.0), (trace.backward, BACKWARD, 0.25)):
        seen = set()
        for e in edges:
            pair = (e.source, e.target)
            if e.source in position and e.target in position and pair not in seen:
                seen.add(pair)
                arrows.append((position[e.source], position[e.target], colour, 0.9, rad))
    for source, target in plan_edges:
        if source in position and target in position:
            arrows.append((position[source], position[target], PLAN, 2.4, 0.0))
    chosen = {s.component for s in plan.steps} if plan else set()
    for iri, (x, y) in position.items():
        virtual = iri in (SRI, SRO, SRE)
        axis.text(
            x,
            y,
            names[iri],
            ha="center",
            va="center",
            fontsize=FONT_SIZE,
            bbox={
                "boxstyle": "round,pad=0.3",
                "fc": "#ffe9a8" if virtual else ("#d8f0d8" if iri in chosen else "#f2f2f2"),
                "ec": PLAN if iri in chosen or virtual else "#999999",
            },
        )
    axis.set_title(local_name(attempt.requirement.iri), fontsize=10)
    ys = [y for _, y in position.values()]
    axis.set_xlim(-0.7, len(columns) - 1 + 0.7)
    axis.set_ylim(min(ys) - 0.8, max(ys) + 0.8)
    axis.axis("off")
    return arrows


def _arrow(
    axis: Axes, start: tuple[float, float], end: tuple[float, float], colour: str, width: float, rad: float
) -> None:
    axis.annotate(
        "",
        xy=end,
        xytext=start,
        annotation_clip=False,  # every end is a vertex inside the axes: no need to test each one
        zorder=2,  # under the vertices' names (texts are 3), which are added first
        arrowprops={
            "arrowstyle": "-|>",
            "color": colour,
            "lw": width,
            "shrinkA": 14,
            "shrinkB": 14,
            "connectionstyle": f"arc3,rad={rad}",
            "alpha": 0.85,
        },
    )
