"""The nineteenth blind round (docs/architecture.md, "Tried by a researcher from Python"): cbrs as a library
from a notebook. The round's script, docs/examples/lab19_notebook.py, runs as the page says (its one
simulation run is PutVialInRack, 10 simulated seconds), and each fault the round found is held fixed: a
knowledge base that shows where its store is, a with block that frees an on-disk store's lock when a cell
fails, a lone path refused naming it, plans whose repr is one short line, the exceptions the knowledge
base raises importable from ``cbrs.kb``, and a docstring on every public method of ``KnowledgeBase``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cbrs.actions import Binding, Composer, Plan, PlanStep, Source
from cbrs.kb import KnowledgeBase, StoreInUseError
from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.reasoner import MatchConfig, Matchmaker

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "examples" / "lab19_notebook.py"
SVC = "https://w3id.org/cbrs/service#"
LAB19 = "https://example.org/lab19#"


@pytest.fixture(scope="module")
def memory() -> KnowledgeBase:
    return KnowledgeBase.open(":memory:")


def test_the_notebook_runs_as_the_page_says() -> None:
    done = subprocess.run([sys.executable, str(NOTEBOOK)], cwd=ROOT, capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr[-3000:]
    lines = done.stdout.splitlines()
    said = "\n".join(lines)
    assert lines[0] == "<KnowledgeBase ':memory:' (EmbeddedStore)>"
    assert "in the kitchen: https://example.org/lab19#Vial1 at (7.90, 3.16)" in lines
    assert "LocateMyVial by sem-str: matched" in lines and "LocateMyVial by string: matched" in lines
    plan = next(line for line in lines if line.startswith("<Plan "))
    assert plan.startswith("<Plan https://example.org/lab19#PutVialInRack (direct): 8 steps [1 svc:")
    assert "8 svc:PutDownObject_CytonDualArm01" in plan and len(plan) < 600
    carry = "svc:CarryObject_CytonDualArm01: (home:PhysicalObject, home:isGraspedBy, home:Gripper) <- #6"
    assert f"  <PlanStep 7 {carry}; targetPlace <- req>" in lines
    assert "ShakeMyVial: unsolvable" in lines
    assert "no component provides effect (https://example.org/lab19#SampleVial, home:isGraspedBy, home:Person)" in said
    slip = "lab19:SampleViall is declared nowhere in the store or in this input (as cbrs:parameterType)"
    assert f"{slip}; did you mean lab19:SampleVial?" in said
    assert "bad query: error at 1:59:" in said and "missing file: lab19_no_such_file.ttl cannot read" in said
    assert (
        "failed update: Vial1 (https://example.org/lab19#Vial1) has home:x 9, home:y 3.16, not over its support" in said
    )
    assert "unknown task: PutVialInRak - PutVialInRack known: True" in lines
    assert "store as it was: True" in lines
    assert "two threads: 6 containers, planned" in lines
    ran = [line for line in lines if line.startswith("run: succeeded in ")]
    assert len(ran) == 1 and ran[0].endswith("simulated s; steps done: 1, 2, 3, 4, 5, 6, 7, 8")
    assert "  goal isLocated: believed True, holds True" in lines
    assert "opened twice: True" in lines and lines[-1] == "reopened: True planned"


def test_a_knowledge_base_shows_where_its_store_is(memory: KnowledgeBase) -> None:
    """It showed ``<cbrs.kb.knowledge_base.KnowledgeBase object at 0x...>``."""
    assert repr(memory) == "<KnowledgeBase ':memory:' (EmbeddedStore)>"


def test_a_with_block_frees_the_store_when_the_cell_fails(tmp_path: Path) -> None:
    """A cell that raised between open and close left the directory locked: opening it again was refused
    until the kernel restarted. KnowledgeBase had no ``__enter__``."""
    folder = tmp_path / "lab"
    with pytest.raises(RuntimeError, match="the cell failed"), KnowledgeBase.open(folder, seed=False) as kb:
        assert repr(kb) == f"<KnowledgeBase {str(folder)!r} (EmbeddedStore)>"
        raise RuntimeError("the cell failed")
    with KnowledgeBase.open(folder, seed=False) as again:
        assert again.statistics() == {}


@pytest.mark.parametrize(
    "lone", ["docs/examples/lab19_vial_and_rack.ttl", Path("docs/examples/lab19_vial_and_rack.ttl")]
)
def test_a_lone_path_is_refused_naming_it(memory: KnowledgeBase, lone: str | Path) -> None:
    """``kb.load("lab.ttl")`` was read character by character: '/: a directory with no RDF file in it' for an
    absolute path; a Path was "'PosixPath' object is not iterable"."""
    before = memory.statistics()
    with pytest.raises(TypeError, match=r"not one \w+: kb\.load\(\['docs/examples/lab19_vial_and_rack\.ttl'\]\)"):
        memory.load(lone, graph="map")  # type: ignore[arg-type]
    assert memory.statistics() == before


def _step(index: int, name: str, bindings: tuple[Binding, ...]) -> PlanStep:
    return PlanStep(index, SVC + name, name, None, None, None, bindings, (), (), 0.5, alternatives=(SVC + "Other",))


def test_a_plan_step_and_binding_show_in_one_short_line() -> None:
    """The dataclass reprs spelt every field in full: 8,154 characters for PutVialInRack's eight steps, and
    a composition holding it 46,869, in a notebook cell that showed the plan."""
    vial = Binding("input", "objectType", Source("vial", None, LAB19 + "PutVialInRack"), "SubClassOf", 0.4, "x")
    pose = Binding("input", "graspPose", Source("graspPose", 2), "Exact", 1.0, "y")
    steps = tuple(_step(n, f"Step{n}_Device01", (vial, pose)) for n in range(1, 9))
    plan = Plan(LAB19 + "PutVialInRack", LAB19 + "PutVialInRack", "direct", steps, (pose,), 0.8119, 11.9)
    shown = repr(plan)
    assert "\n" not in shown and len(shown) < 500
    assert shown.startswith("<Plan https://example.org/lab19#PutVialInRack (direct): 8 steps [1 svc:Step1_Device01, ")
    assert shown.endswith("8 svc:Step8_Device01], 1 goal, similarity 0.812, cost 11.9>")
    assert repr(steps[0]) == "<PlanStep 1 svc:Step1_Device01: objectType <- req; graspPose <- #2, 1 alternative(s)>"
    assert repr(vial) == "<Binding input objectType <- vial of the requirement, SubClassOf 0.40>"
    assert repr(pose) == "<Binding input graspPose <- step 2, Exact 1.00>"


def test_the_errors_a_knowledge_base_raises_come_from_cbrs_kb() -> None:
    """A failed update's MapError, a refused description's DescriptionShapeError and a locked store's
    StoreInUseError had to be imported from the modules that raise them."""
    import cbrs.kb
    from cbrs.kb.semantic_map import MapError
    from cbrs.kb.shapes import DescriptionShapeError
    from cbrs.kb.store import StoreInUseError

    assert cbrs.kb.MapError is MapError
    assert cbrs.kb.DescriptionShapeError is DescriptionShapeError
    assert cbrs.kb.StoreInUseError is StoreInUseError
    assert {"MapError", "DescriptionShapeError", "StoreInUseError"} <= set(cbrs.kb.__all__)


def test_every_public_method_of_a_knowledge_base_says_what_it_is_for() -> None:
    """``help(kb.query)``, ``select``, ``description``, ``requirements`` and ``close`` said nothing."""
    undocumented = sorted(
        name for name in dir(KnowledgeBase) if not name.startswith("_") and not getattr(KnowledgeBase, name).__doc__
    )
    assert undocumented == []


def test_the_package_says_where_its_library_is() -> None:
    """``help(cbrs)`` said one sentence about the service: nothing of the four packages a program imports."""
    import cbrs

    assert cbrs.__doc__ is not None
    for name in ("cbrs.kb", "KnowledgeBase.open", "cbrs.reasoner", "Matchmaker", "cbrs.actions", "Composer"):
        assert name in cbrs.__doc__
    assert "run_task" in cbrs.__doc__ and "cbrs.sim" in cbrs.__doc__


def test_a_store_open_twice_in_one_kernel_says_to_close_the_other(tmp_path: Path) -> None:
    """A second open in the same kernel said "in use by another process ... stop that process": there was
    none, only the notebook's own KnowledgeBase from an earlier cell."""
    folder = tmp_path / "lab"
    with KnowledgeBase.open(folder, seed=False), pytest.raises(StoreInUseError, match="by this process") as refused:
        KnowledgeBase.open(folder, seed=False)
    assert "close the KnowledgeBase" in str(refused.value)


def test_a_load_report_a_composition_and_a_ranking_show_in_a_few_lines() -> None:
    """A load's report printed every quad it loaded, a composition its search's graphs and traces (31,383
    characters for an eight-step plan), a ranking ``<_Ranking object at 0x...>``."""
    with KnowledgeBase.open(":memory:") as kb:
        report = kb.load([ROOT / "docs" / "examples" / "lab19_vial_and_rack.ttl"], graph="ontology")
        assert "Quad(" not in repr(report) and len(repr(report)) < 2_000
        composition = Composer(kb).compose("FetchMyPen")
        assert composition.plan is not None and len(repr(composition)) < 5_000
        assert "attempts=" not in repr(composition)
        ranking = Matchmaker(kb, "sem-str", MatchConfig()).rank(kb.requirements()[0], explain=3)
        shown = repr(ranking.candidates)
        assert shown.startswith(f"<{len(ranking.candidates)} candidates: ") and "object at" not in shown


def test_a_requirement_is_ranked_by_its_short_name_as_cbrs_match_takes_it(memory: KnowledgeBase) -> None:
    """``Matchmaker.rank("RobotSelfPosition")`` failed with a BindingError about an internal parameter, where
    ``cbrs match RobotSelfPosition`` and ``Composer.compose`` take the short name."""
    matchmaker = Matchmaker(memory, "sem-str", MatchConfig())
    full = matchmaker.rank("https://w3id.org/cbrs/requirement#RobotSelfPosition", explain=1)
    for name in ("RobotSelfPosition", "req:RobotSelfPosition"):
        ranked = matchmaker.rank(name, explain=1)
        assert ranked.requirement == full.requirement
        assert ranked.candidates[0].advertisement == full.candidates[0].advertisement
    with pytest.raises(UnknownPrefixError, match=r"reqq:RobotSelfPosition.*did you mean req:RobotSelfPosition"):
        matchmaker.rank("reqq:RobotSelfPosition")  # a misspelt prefix, not an IRI of scheme reqq that names nothing


def test_an_advertisement_and_a_requirement_show_in_one_short_line(memory: KnowledgeBase) -> None:
    """The generated repr of one bundled advertisement spelt its part trees in full, 1-4 KB each, so a
    notebook listing ``kb.advertisements()[:3]`` filled the screen; ``to_dict`` still gives every field."""
    advertisements, requirements = memory.advertisements(), memory.requirements()
    for description in [*advertisements, *requirements]:
        shown = repr(description)
        assert shown.startswith(f"<{type(description).__name__} {description.iri!r}")
        assert len(shown) < 300 and "PartNode" not in shown
    carry = next(a for a in advertisements if a.iri == SVC + "CarryObject_CytonDualArm01")
    assert repr(carry) == (
        f"<Advertisement {carry.iri!r} 'Carry object (Cyton dual arm 1)': 1 input, 1 precondition, 1 effect>"
    )
    assert carry.to_dict()["inputs"][0]["tree"] is not None
