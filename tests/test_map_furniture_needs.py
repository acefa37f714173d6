"""What a lab's furniture needs for the simulation to use it, refused or warned of before a run moves
(the fourth round's two failures, docs/tasks.md "A fourth round").

A bench typed as furniture with no extent was loaded without a word, ``cbrs home`` passed it, and a task
putting the pen on it failed mid-run with a ``KeyError``: the map reader now refuses it (``NoExtentError``,
naming the bench and the properties it lacks), so the load, ``POST /store``, ``/home.json``, ``cbrs home``
and a run agree. A trolley the torch lies on with no docking pose failed the fetch at InferObjectPlace with
"the knowledge base does not say where the Torch1 is kept": the home check now lists such supports
(``undocked_supports``), and the place inference names the trolley and ``home:dockingPose``. No world is
built: the reader and the checks work on the store."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.app import App
from cbrs.cli import cli
from cbrs.cli_home import home
from cbrs.home_plan import survey
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import NoDockingPoseError, Undocked, check_home, docked_place, undocked_supports
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.semantic_map import NoExtentError, SemanticMap
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.services import infer_object_place, kept_place
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
BENCH = EXAMPLES / "lab4_mistake_bench_without_extent.ttl"
HOME, GRAPH, LAB = PREFIXES["home"], PREFIXES["graph"], "https://example.org/lab4#"
WORLD = "https://w3id.org/cbrs/world#"
TOKEN = "furniture-token"
EXTENT = ["home:minX", "home:maxX", "home:minY", "home:maxY", "home:maxZ"]


def _map(kb: KnowledgeBase) -> list[ox.Quad]:
    return sorted(kb.store.quads(graph=GraphName.MAP.node), key=str)


@pytest.fixture
def kb() -> Iterator[KnowledgeBase]:
    """The bundled home, with the bench's class in the ontology (as the trial loaded it first)."""
    opened = KnowledgeBase.open(":memory:")
    opened.load([BENCH], graph="ontology")
    yield opened
    opened.close()


def test_a_bench_without_an_extent_is_refused_at_load_naming_it_and_what_it_lacks(kb: KnowledgeBase) -> None:
    before = _map(kb)
    with pytest.raises(NoExtentError) as refused:
        kb.load([BENCH], graph="map")
    assert refused.value.thing == LAB + "Bench1"
    assert list(refused.value.missing) == EXTENT
    said = str(refused.value)
    assert "Bench1" in said and "is a Bench with no extent" in said and "home:minX" in said
    assert _map(kb) == before


def test_a_partial_extent_names_only_what_is_missing_and_a_slip(kb: KnowledgeBase, tmp_path: Path) -> None:
    """A bench with its top and a misspelt home:minx: the hint points at the slip, as a missing
    required property's does."""
    bench = tmp_path / "bench.ttl"
    bench.write_text(
        f"@prefix home: <{HOME}> .\n@prefix lab: <{LAB}> .\n"
        "lab:Bench2 a lab:Bench ; home:minx 8.9 ; home:maxZ 0.45 .\n",
        encoding="utf-8",
    )
    with pytest.raises(NoExtentError) as refused:
        kb.load([bench], graph="map")
    assert list(refused.value.missing) == EXTENT[:4]
    assert "did you mean home:minX for its home:minx?" in str(refused.value)


def test_the_bench_is_refused_over_http_and_the_store_is_as_it_was(kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()
    before = _map(kb)
    response = client.post(
        f"/store?graph={GRAPH}map",
        data=BENCH.read_bytes(),
        headers={"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"},
    )
    assert response.status_code == 422
    answer = response.get_json()
    assert "Bench1" in answer["message"] and "no extent" in answer["message"], answer
    assert _map(kb) == before


def test_a_map_that_holds_such_a_bench_is_unreadable_to_cbrs_home_and_the_home_page(tmp_path: Path) -> None:
    """A load refuses the bench; written past the checks (into the store directly), it makes the map
    unreadable, and ``cbrs home`` and ``/home.json`` say so by name, as a run's read of the map does (they
    said "the simulation can build this home")."""
    store, runner = str(tmp_path / "store"), CliRunner()
    kb = KnowledgeBase.open(store)
    try:
        kb.load([BENCH], graph="ontology")
        with pytest.raises(NoExtentError, match="nothing was loaded"):
            kb.load([BENCH], graph="map")
        parsed = ox.parse(BENCH.read_bytes(), ox.RdfFormat.TURTLE)
        kb.store.add(ox.Quad(t.subject, t.predicate, t.object, GraphName.MAP.node) for t in parsed)
        found = survey(kb)
        assert found.verdict == "unreadable" and isinstance(found.problem, NoExtentError)
        client = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()
        page = client.get("/home.json").get_json()
        assert page["verdict"] == "unreadable" and "Bench1" in page["problem"]["message"], page
    finally:
        kb.close()
    home = runner.invoke(cli, ["--store", store, "home"])
    assert home.exit_code == 1, home.output
    assert "cannot be read" in home.output and "Bench1" in home.output and "no extent" in home.output


@pytest.fixture(scope="module")
def undocked() -> Iterator[KnowledgeBase]:
    """The bundled home with the fourth round's trolley and torch, the trolley's docking pose left out."""
    text = (EXAMPLES / "lab4_trolley.ttl").read_text(encoding="utf-8")
    text = text.replace(" ;\n    home:dockingPose lab:Trolley1Dock .", " .")
    assert "home:dockingPose" not in text
    opened = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        opened.store.add(
            ox.Quad(t.subject, t.predicate, t.object, ox.NamedNode(GRAPH + graph))
            for t in ox.parse(text.encode(), ox.RdfFormat.TURTLE)
        )
    yield opened
    opened.close()


def test_a_trolley_holding_the_torch_without_a_docking_pose_is_built_and_warned_of(undocked: KnowledgeBase) -> None:
    smap = SemanticMap.read(undocked)
    check_home(smap)  # the arms may reach it: no refusal of the home
    assert undocked_supports(smap) == [Undocked(LAB + "Trolley1", (LAB + "Torch1",))]
    said = undocked_supports(smap)[0].said
    assert said.startswith("Trolley1 holds Torch1 and has no home:dockingPose")


def test_cbrs_home_and_the_home_page_warn_of_the_trolley_without_a_docking_pose(undocked: KnowledgeBase) -> None:
    """A warning, not a refusal: the text, the JSON and /home.json say it; the page shows it."""
    runner = CliRunner()
    text = runner.invoke(home, [], obj=App(":memory:", undocked))
    assert text.exit_code == 0, text.output
    assert "warning: Trolley1 holds Torch1 and has no home:dockingPose" in text.output
    said = json.loads(runner.invoke(home, ["--json"], obj=App(":memory:", undocked)).output)
    assert said["verdict"] == "ok" and [w.split(":")[0] for w in said["warnings"]] == [
        "Trolley1 holds Torch1 and has no home"
    ]
    client = create_app(SparqlService(undocked, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()
    assert client.get("/home.json").get_json()["warnings"] == said["warnings"]
    assert "Trolley1 holds Torch1 and has no home:dockingPose" in client.get("/home").get_data(as_text=True)


def test_the_bundled_home_holds_nothing_on_a_support_without_a_docking_pose() -> None:
    bundled = KnowledgeBase.open(":memory:")
    try:
        assert undocked_supports(SemanticMap.read(bundled)) == []
    finally:
        bundled.close()


def test_the_place_of_an_object_is_the_first_support_with_a_docking_pose(undocked: KnowledgeBase) -> None:
    smap = SemanticMap.read(undocked)
    table, trolley, torch = WORLD + "KitchenTable", LAB + "Trolley1", LAB + "Torch1"
    with pytest.raises(NoDockingPoseError) as refused:
        docked_place(smap, torch, [WORLD + "Kitchen", trolley])  # a room it is in is no support
    assert refused.value.thing == torch and refused.value.supports == (trolley,)
    assert "is on Trolley1 (home:isLocatedOn), which has no home:dockingPose" in str(refused.value)
    place = docked_place(smap, torch, [trolley, table])
    assert place is not None and place.iri == table
    assert docked_place(smap, torch, [WORLD + "Kitchen", LAB + "Nowhere"]) is None


def test_inferring_where_the_torch_is_kept_names_the_trolley_and_its_missing_docking_pose(
    undocked: KnowledgeBase,
) -> None:
    """The home server's step, on the map alone (a stand-in world that only holds the map): it said "the
    knowledge base does not say where the Torch1 is kept, or how to reach it"."""
    ctx = SimContext(world=SimpleNamespace(map=SemanticMap.read(undocked), arm_specs={}), kb=undocked)  # type: ignore[arg-type]
    with pytest.raises(NoDockingPoseError):  # what a check before the run can ask
        kept_place(ctx, LAB + "Torch1")
    with pytest.raises(SkillFailed) as failed:
        infer_object_place(ctx, {"object": {"@id": LAB + "Torch1"}}, "HomeServer01")
    assert "Torch1" in str(failed.value) and "Trolley1" in str(failed.value)
    assert "home:dockingPose" in str(failed.value)


def test_fetching_the_torch_from_the_trolley_without_a_docking_pose_is_refused_before_anything_moves(
    tmp_path: Path,
) -> None:
    """The run's checks ask where the object is kept before the base drives: the refusal names the trolley
    and the docking pose it lacks, with nothing moved (it failed at the step that infers where the torch is
    kept, after a localisation and a re-plan)."""
    trolley = tmp_path / "trolley.ttl"
    text = (EXAMPLES / "lab4_trolley.ttl").read_text(encoding="utf-8")
    trolley.write_text(text.replace(" ;\n    home:dockingPose lab:Trolley1Dock .", " ."), encoding="utf-8")
    store, runner = str(tmp_path / "store"), CliRunner()
    loads = [
        ("ontology", trolley),
        ("map", trolley),
        ("map", EXAMPLES / "lab4_trolley_camera_map.ttl"),
        ("services", EXAMPLES / "lab4_trolley_camera.ttl"),
        ("requirements", EXAMPLES / "lab4_fetch_my_torch.ttl"),
    ]
    for graph, path in loads:
        loaded = runner.invoke(cli, ["--store", store, "load", "--graph", graph, str(path)])
        assert loaded.exit_code == 0, loaded.output
    done = runner.invoke(cli, ["--store", store, "run", "FetchMyTorch", "--seed", "0", "--json"])
    assert done.exit_code == 1, done.output
    said = json.loads(done.stdout)  # the answer of a refusal before anything moved: no steps, no seconds
    assert said["status"] == "error" and said["error"].startswith("NoDockingPoseError"), said
    assert "Trolley1 (home:isLocatedOn), which has no home:dockingPose" in said["error"], said
