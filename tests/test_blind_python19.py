"""The nineteenth blind round (docs/architecture.md, "Tried by a researcher from Python"): cbrs as a library
from a notebook. The round's script, docs/examples/lab19_notebook.py, runs as the page says (its one
simulation run is PutVialInRack, 10 simulated seconds), and each fault the round found is held fixed: a
knowledge base that shows where its store is, a with block that frees an on-disk store's lock when a cell
fails, a lone path refused naming it, plans whose repr is one short line, the exceptions the knowledge
base raises importable from ``cbrs.kb``, and a docstring on every public method of ``KnowledgeBase``."""

from __future__ import annotations

from cbrs.actions import Binding, Plan, PlanStep, Source

SVC = "https://w3id.org/cbrs/service#"
LAB19 = "https://example.org/lab19#"


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
