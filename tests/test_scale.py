"""Behaviour that keeps cbrs fast at start-up and at scale (issue 18); the figures are in bench/."""

from __future__ import annotations

import importlib
import subprocess
import sys

import click
import pytest
from click.testing import CliRunner

from cbrs.actions.composer import ComposeConfig, Composer, Objective, PlanStatus
from cbrs.actions.model import ActionLibrary
from cbrs.bridge_services import KnowledgeServices
from cbrs.cli import _LAZY_COMMANDS, cli
from cbrs.kb import Advertisement, KnowledgeBase, Parameter, Requirement
from cbrs.reasoner import synthetic, vectors
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRunner

# -- start-up ------------------------------------------------------------------------------------


def _imported_after(statement: str, modules: tuple[str, ...]) -> list[str]:
    """The ``modules`` a fresh interpreter has imported after running ``statement``."""
    code = f"import sys\n{statement}\nprint(' '.join(m for m in {modules!r} if m in sys.modules))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.split()


def test_the_cli_imports_no_heavy_library() -> None:
    heavy = ("numpy", "networkx", "sklearn", "scipy", "werkzeug", "httpx", "cbrs.actions", "cbrs.reasoner")
    assert _imported_after("import cbrs.cli", heavy) == []


def test_the_reasoner_loads_scikit_learn_and_numpy_only_when_ranking() -> None:
    assert _imported_after("import cbrs.reasoner, cbrs.actions", ("sklearn", "scipy", "numpy")) == []


@pytest.mark.parametrize("name", sorted(_LAZY_COMMANDS))
def test_a_lazy_command_is_listed_with_its_own_help(name: str) -> None:
    module, attribute, text = _LAZY_COMMANDS[name]
    command = getattr(importlib.import_module(module), attribute)
    assert command.name == name
    stand_in = click.Command(name, help=text)
    for limit in (20, 45, 70, 200):
        assert stand_in.get_short_help_str(limit) == command.get_short_help_str(limit)


def test_help_lists_every_command_and_each_lazy_one_runs() -> None:
    listed = CliRunner().invoke(cli, ["--help"]).output
    for name in _LAZY_COMMANDS:
        assert f"\n  {name} " in listed
        shown = CliRunner().invoke(cli, [name, "--help"])
        assert shown.exit_code == 0, shown.output
        assert f"Usage: cli {name}" in shown.output


# -- composition over a large pool --------------------------------------------------------------

N = 10_000  # converters: ad{i} takes concept C{i} and gives C{i+1}
NS = "http://example.org/scale#"


def _concept(i: int) -> str:
    return f"{NS}C{i}"


@pytest.fixture(scope="module")
def chain_composer() -> Composer:
    """A pool of ``N`` advertisements, each the next link of one long chain: the longest explanation
    a pool of that size can need, and a short plan at its end."""
    index = TaxonomyIndex.from_links(
        [Link(_concept(i), ROOT, "is-a") for i in range(N + 1)] + [Link(NS + "X", ROOT, "is-a")]
    )
    pool = [
        Advertisement(
            iri=f"{NS}ad{i}",
            types=(),
            inputs=(Parameter(f"{NS}ad{i}in", "input", _concept(i)),),
            outputs=(Parameter(f"{NS}ad{i}out", "output", _concept(i + 1)),),
        )
        for i in range(N)
    ]
    kb = KnowledgeBase.open(":memory:")
    return Composer(kb, ComposeConfig(matched=False), index=index, actions=ActionLibrary(), advertisements=pool)


def _requirement(given: str, wanted: str) -> Requirement:
    return Requirement(
        iri=NS + "req",
        types=(),
        inputs=(Parameter(NS + "given", "input", given),),
        outputs=(Parameter(NS + "wanted", "output", wanted),),
    )


def test_a_blocked_chain_as_long_as_the_pool_is_explained_to_its_root(chain_composer: Composer) -> None:
    result = chain_composer.compose(_requirement(NS + "X", _concept(N)))
    assert result.status is PlanStatus.UNSOLVABLE
    [cause] = result.unsatisfied
    assert cause.consumer == f"{NS}ad0"  # nothing gives C0: the root of every link's failure
    assert len(cause.chain) == N + 1  # the requirement's output, then every advertisement followed
    assert not cause.cycle


def test_a_plan_at_the_end_of_a_large_pool(chain_composer: Composer) -> None:
    result = chain_composer.compose(_requirement(_concept(N - 5), _concept(N)))
    assert result.status is PlanStatus.PLANNED
    assert result.plan is not None
    assert [c.removeprefix(NS) for c in result.plan.components()] == [f"ad{i}" for i in range(N - 5, N)]


# -- /cbrs/plan keeps its composer ---------------------------------------------------------------

CAMERA = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"


def _planned_components(services: KnowledgeServices) -> list[str]:
    answer = services.plan({"task": "FetchMyPen"})
    assert answer["status"] == "planned"
    return [step["component"] for step in answer["steps"]]


@pytest.fixture
def services() -> KnowledgeServices:
    kb = KnowledgeBase.open(":memory:")
    sparql = SparqlService(kb)
    return KnowledgeServices(sparql, TaskRunner(kb, sparql.lock, camera=None))


def test_plan_calls_share_a_composer_until_the_store_changes(services: KnowledgeServices) -> None:
    first = _planned_components(services)
    composer = services.composers.get(Objective.SIMILARITY)
    assert (
        _planned_components(services) == first == Composer(services.sparql.kb).compose("FetchMyPen").plan.components()
    )  # type: ignore[union-attr]
    assert services.composers.get(Objective.SIMILARITY) is composer
    assert CAMERA in first

    services.sparql.kb.registry.deregister(CAMERA)
    services.sparql.changed()  # as a registration or an update through the endpoint does
    assert CAMERA not in _planned_components(services)
    assert services.composers.get(Objective.SIMILARITY) is not composer


def test_plans_and_rankings_share_one_taxonomy_index_per_store_version(services: KnowledgeServices) -> None:
    ranked = services.matchmakers.get("sem-str")
    composer = services.composers.get(Objective.SIMILARITY)
    assert composer.index is ranked.index is services.matchmakers.index()
    services.sparql.changed()
    fresh = services.composers.get(Objective.SIMILARITY)
    assert fresh.index is not composer.index
    assert services.matchmakers.get("sem-str").index is fresh.index


def test_a_component_whose_lease_lapsed_is_planned_without(services: KnowledgeServices) -> None:
    assert CAMERA in _planned_components(services)
    services.sparql.kb.liveness.expire(CAMERA, "lease lapsed")  # no store generation: seen at the next call
    assert CAMERA not in _planned_components(services)


# -- the matchmaker's caches are bounded ---------------------------------------------------------


def test_bounded_vector_caches_rank_as_unbounded_ones(monkeypatch: pytest.MonkeyPatch) -> None:
    index, pool, requirements = synthetic.build(400, 60, 12, seed=3)
    kb = KnowledgeBase.open(":memory:")
    expected = [_order(Matchmaker(kb, index=index, advertisements=pool), r) for r in requirements]
    monkeypatch.setattr(vectors, "ARRAY_CACHE_BYTES", 3 * 8 * 401)  # three vectors of the taxonomy
    matchmaker = Matchmaker(kb, index=index, advertisements=pool)
    assert [_order(matchmaker, r) for r in requirements * 2] == expected * 2
    space = matchmaker._compiled(matchmaker.advertisements).space
    for cache in (space._cache, space._lcs, space._floors, space._parts_masks, space._disjoint):
        assert cache.weight <= 3 * 8 * len(space) or len(cache) == 1


def _order(matchmaker: Matchmaker, requirement: Requirement) -> list[tuple[str, float]]:
    return [(c.advertisement, c.score) for c in matchmaker.rank(requirement, explain=3).candidates]
