"""Execution driven by the knowledge base: tasks, objects and places written only in Turtle run in a
simulated home built from the store's semantic map (tests/data/tasks holds the files). The pencil
fetched by a goal-only task runs from the tasks page, under a namespace of its own
(tests/test_tasks_from_the_store.py, which checks its step order and the world graph as well)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.events import Event
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import AmbiguousDesignatorError, MapError, SemanticMap, UnresolvedDesignatorError, designate
from cbrs.sim.components import SimEnvironment
from cbrs.sim.mapping import build_occupancy_grid
from cbrs.sim.world import HomeWorld, open_world

TASKS = Path(__file__).parent / "data" / "tasks"
HOME, WORLD, REQ = PREFIXES["home"], PREFIXES["world"], PREFIXES["req"]


def knowledge(*files: tuple[str, str]) -> KnowledgeBase:
    """A fresh knowledge base with the given (graph, file of tests/data/tasks) loaded."""
    kb = KnowledgeBase.open(":memory:")
    for graph, name in files:
        kb.load([TASKS / name], graph=graph)
    return kb


def run(kb: KnowledgeBase, task: str, seed: int = 0) -> RunResult:
    with open_world(seed=seed, semantic_map=SemanticMap.read(kb)) as world:
        return run_task(kb, task, SimEnvironment(world, kb), composer=Composer(kb))


def world_facts(kb: KnowledgeBase) -> set[tuple[str, str, str]]:
    return {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}


def test_a_new_destination_written_in_turtle() -> None:
    kb = knowledge(("map", "tray_place.ttl"), ("requirements", "put_cup_on_tray.ttl"))
    result = run(kb, "PutCupOnTray")
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert (WORLD + "Cup", HOME + "isLocated", WORLD + "TrayPlace") in world_facts(kb)


def test_moving_the_cup_in_the_store_moves_it_in_the_simulation() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "DELETE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } } "
        "INSERT { GRAPH graph:map { world:Cup home:x 7.30 ; home:y 3.60 } } "
        "WHERE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } }"
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        x, y, z = world.pose("Cup").position
    assert abs(x - 7.30) < 0.03 and abs(y - 3.60) < 0.03
    assert abs(z - (0.75 + 0.05)) < 0.01  # resting on the table it is said to be on


def test_a_book_added_without_a_grasp_says_what_to_add() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "INSERT DATA { GRAPH graph:map { world:Book1 a home:Book ; home:shapeKind 'box' ; home:sizeX 0.2 ; "
        "home:sizeY 0.15 ; home:sizeZ 0.03 ; home:massKg 0.4 ; home:x 8.2 ; home:y 4.0 ; "
        "home:isLocatedOn world:KitchenTable } }"
    )
    ungraspable = SemanticMap.read(kb).objects[WORLD + "Book1"]  # read: what nothing takes may lack a grasp
    assert ungraspable.grasp_approaches == ()
    with pytest.raises(MapError, match="graspApproach") as refused:
        _ = ungraspable.grasp_approach
    assert refused.value.thing == WORLD + "Book1"
    affordance = "home:graspApproach 'top' ; home:graspHeightRatio 0.5"
    kb.update(f"INSERT DATA {{ GRAPH graph:ontology {{ <{HOME}Book> {affordance} }} }}")
    book = SemanticMap.read(kb).objects[WORLD + "Book1"]
    assert (book.grasp_approach, book.grasp_height) == ("top", pytest.approx(0.015))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        x, y, _ = world.pose("Book1").position
    assert abs(x - 8.2) < 0.03 and abs(y - 4.0) < 0.03


def test_an_input_is_resolved_by_its_class_and_ambiguity_names_the_candidates() -> None:
    kb = KnowledgeBase.open(":memory:")
    assert designate(kb, HOME + "Drinkware") == WORLD + "Cup"  # by the taxonomy, not by name
    kb.update("INSERT DATA { GRAPH graph:map { world:Mug1 a home:Mug } }")
    with pytest.raises(AmbiguousDesignatorError) as ambiguous:
        designate(kb, HOME + "Drinkware")
    assert ambiguous.value.candidates == [WORLD + "Cup", WORLD + "Mug1"]
    assert "Cup, Mug1" in str(ambiguous.value)
    with pytest.raises(UnresolvedDesignatorError, match="nothing in the world is a Bottle"):
        designate(kb, HOME + "Bottle")


def test_a_robots_preference_follows_its_things_not_its_numbers() -> None:
    """With two pens, the requesting robot's own things win; its literal facts (``home:y 1.5``) are no
    things to follow: looking them up as IRIs broke every task with two things of an input's class."""
    kb = KnowledgeBase.open(":memory:")
    kb.update("INSERT DATA { GRAPH graph:map { world:Pen2 a home:Pen ; home:x 7.9 ; home:y 3.4 } }")
    with pytest.raises(AmbiguousDesignatorError) as ambiguous:
        designate(kb, HOME + "Pen", prefer=PREFIXES["svc"] + "P3DX01")
    assert ambiguous.value.candidates == [WORLD + "Pen", WORLD + "Pen2"]
    assert designate(kb, HOME + "ColourMarker", prefer=PREFIXES["svc"] + "P3DX01")  # its own marker, as before


def test_the_ambiguity_advice_can_be_followed_a_class_of_its_own_names_one_thing() -> None:
    """The refusal said to "name the individual in the task", which a task cannot (an input names a
    class); it now says to give the thing a class of its own, and that class designates it."""
    kb = KnowledgeBase.open(":memory:")
    kb.update("INSERT DATA { GRAPH graph:map { world:Pen2 a home:Pen ; home:x 7.9 ; home:y 3.4 } }")
    with pytest.raises(AmbiguousDesignatorError) as ambiguous:
        designate(kb, HOME + "Pen")
    said = str(ambiguous.value)
    assert "world:Pen a world:MyPen . world:MyPen rdfs:subClassOf home:Pen" in said and "cbrs:parameterType" in said
    lab = "https://example.org/lab#"
    kb.update(
        f"INSERT DATA {{ GRAPH graph:map {{ <{lab}MyPen> a owl:Class ; rdfs:subClassOf home:Pen . "
        f"world:Pen2 a <{lab}MyPen> }} }}"
    )
    assert designate(kb, lab + "MyPen") == WORLD + "Pen2"


def test_a_task_whose_input_has_no_thing_in_the_world_says_which(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    task = (TASKS / "fetch_my_pencil.ttl").read_text(encoding="utf-8")
    kb.load([TASKS / "fetch_my_pencil.ttl"], graph="requirements")
    assert "Pencil" in task
    with pytest.raises(UnresolvedDesignatorError, match="Pencil"):
        run(kb, "FetchMyPencil")


def test_a_store_seeded_before_the_semantic_map_gets_it_on_open(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(tmp_path / "store")
    kb.update("DROP GRAPH graph:map")
    kb.update(f"DELETE WHERE {{ GRAPH graph:ontology {{ ?class <{HOME}graspApproach> ?approach }} }}")
    before = kb.store.count()
    kb.store.close()
    reopened = KnowledgeBase.open(tmp_path / "store")
    assert reopened.store.count() > before
    assert WORLD + "Cup" in SemanticMap.read(reopened).objects  # with its inherited grasp again


def test_a_store_with_an_older_map_gets_the_new_statements_and_keeps_what_the_user_moved(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(tmp_path / "store")
    robot = PREFIXES["svc"] + "P3DX01"
    kb.update(  # what a store seeded by the previous version looks like: no footprint, version 0.1.0
        f"""DELETE WHERE {{ GRAPH graph:map {{ <{robot}> home:sizeX ?x ; home:sizeY ?y .
                                          <https://w3id.org/cbrs/world> owl:versionInfo ?v }} }}""",
        check_map=False,  # a map the current reader refuses, on purpose (the later updates find it unreadable)
    )
    kb.update("INSERT DATA { GRAPH graph:map { <https://w3id.org/cbrs/world> owl:versionInfo '0.1.0' } }")
    kb.update(f"DELETE WHERE {{ GRAPH graph:map {{ <{WORLD}Cup> home:x ?x }} }}")
    # the user moved the cup (to a value that sorts after the bundled 7.45: no reader may pick by order)
    kb.update(f"INSERT DATA {{ GRAPH graph:map {{ <{WORLD}Cup> home:x 7.6 }} }}")
    with pytest.raises(MapError, match=r"P3DX01.*home:sizeX"):
        SemanticMap.read(kb)
    kb.store.close()
    reopened = SemanticMap.read(KnowledgeBase.open(tmp_path / "store"))
    assert reopened.robots[robot].footprint == (0.45, 0.38)
    assert reopened.objects[WORLD + "Cup"].start.x == 7.6


def test_two_values_for_one_pose_are_refused_naming_both() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(f"INSERT DATA {{ GRAPH graph:map {{ <{WORLD}Cup> home:x 7.3 }} }}", check_map=False)  # only adds
    with pytest.raises(MapError, match=r"Cup.*home:x '7\.3\d*' and '7\.\d+'.*one value") as refused:
        SemanticMap.read(kb)
    assert refused.value.thing == WORLD + "Cup"


def test_a_wall_written_in_turtle_is_built_and_mapped() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        f"""INSERT DATA {{ GRAPH graph:map {{
            <{WORLD}Partition> a home:Wall ; home:minX 4.0 ; home:maxX 4.1 ; home:minY 3.0 ; home:maxY 4.5 ;
                home:minZ 0.0 ; home:maxZ 1.0 . }} }}"""
    )
    with open_world(semantic_map=SemanticMap.read(kb)) as world:
        assert "Partition" in world.bodies
        grid = build_occupancy_grid(world)
        assert grid.is_occupied(4.05, 3.75)
    with open_world() as bundled:
        assert not build_occupancy_grid(bundled).is_occupied(4.05, 3.75)


def test_a_better_camera_registered_in_turtle_is_used_by_fetch_my_pen() -> None:
    kb = knowledge(("services", "better_camera.ttl"), ("map", "better_camera_on_the_ceiling.ttl"))
    result = run(kb, "FetchMyPen")
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert result.report is not None
    used = [step.attempts[-1].component for step in result.report.steps if step.attempts]
    assert PREFIXES["svc"] + "LocateMobileRobot_CeilingCamera03" in used
    assert len(result.report.steps) == 15


def _moving(world: HomeWorld, after: str, body: str, to: tuple[float, float]) -> Callable[[Event], None]:
    """An event listener that moves ``body`` once, right after the step of ``after`` succeeds."""
    moved: list[bool] = []

    def listen(event: Event) -> None:
        message = event.message
        if not moved and message.get("event") == "step_succeeded" and str(message.get("component", "")).endswith(after):
            world.place(body, *to)
            moved.append(True)

    return listen


def run_with(kb: KnowledgeBase, task: str, change: tuple[str, str, tuple[float, float]]) -> RunResult:
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        listener = _moving(world, *change)
        return run_task(kb, task, SimEnvironment(world, kb), composer=Composer(kb), on_event=listener)


def test_the_person_walking_away_before_the_delivery_is_caught_and_replanned() -> None:
    kb = KnowledgeBase.open(":memory:")
    result = run_with(kb, "FetchMyPen", ("NavigateToPerson_P3DX01", "Person", (3.6, 3.9)))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert len(result.replans) == 1  # one new plan, on a map measured afresh
    assert "DeliverObject" in result.replans[0].reason
    assert result.report is not None
    new_plan = [step.planned.rsplit("#", 1)[-1] for step in result.report.steps]
    # the pen is already on the platform: the new plan goes straight to the person
    assert "HandOverOntoPlatform_CytonDualArm01" not in new_plan
    assert new_plan[-1] == "DeliverObject_P3DX01"
    assert (WORLD + "Pen", HOME + "isWith", WORLD + "Person") in world_facts(kb)


def test_the_pen_moved_after_it_was_seen_is_found_again() -> None:
    kb = KnowledgeBase.open(":memory:")
    result = run_with(kb, "FetchMyPen", ("RecogniseObjectByColour_Kinect01", "Pen", (7.98, 3.22)))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert len(result.replans) == 1
    assert (WORLD + "Pen", HOME + "isWith", WORLD + "Person") in world_facts(kb)


def test_a_task_runs_in_a_home_whose_table_was_moved_and_a_second_table_added() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(  # the kitchen table 15 cm further east (the docking pose is where the arm reaches: it stays)
        "DELETE { GRAPH graph:map { ?t home:minX ?a ; home:maxX ?b } } "
        "INSERT { GRAPH graph:map { ?t home:minX ?a2 ; home:maxX ?b2 } } "
        "WHERE { GRAPH graph:map { VALUES ?t { world:KitchenTable world:KitchenTableTop } "
        "?t home:minX ?a ; home:maxX ?b } BIND(?a + 0.15 AS ?a2) BIND(?b + 0.15 AS ?b2) } ; "
        "INSERT DATA { GRAPH graph:map { world:LivingRoomTable a home:Table ; home:minX 1.0 ; home:maxX 1.8 ; "
        "home:minY 0.5 ; home:maxY 1.1 ; home:minZ 0.0 ; home:maxZ 0.7 } }"
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        assert world.furniture == ["KitchenTable", "LivingRoomTable"]
        low, high = world.aabb("KitchenTable")
        assert abs(low[0] - 7.15) < 0.01 and abs(high[0] - 8.65) < 0.01
        assert abs(world.aabb("LivingRoomTable")[1][2] - 0.7) < 0.01
        result = run_task(kb, "FetchMyPen", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied


def test_the_papers_table_2_requirement_plans_and_runs_on_the_camera_the_matchmaker_ranks_first() -> None:
    kb = KnowledgeBase.open(":memory:")
    result = run(kb, "RobotSelfPosition")
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    plan = result.composition.plan
    assert plan is not None and plan.method == "matched"  # no is-a chain gives a RobotPosition: Table 3's match
    assert [step.component for step in plan.steps] == [PREFIXES["svc"] + "LocateMobileRobot_CeilingCamera01"]
    assert [(goal.name, goal.source.name) for goal in plan.goals] == [("selfPosition", "robotLocation")]


@pytest.mark.parametrize(
    ("task", "files", "fact"),
    [
        pytest.param(
            "FetchMyPencilLikeMyPen",
            [("map", "pencil_on_the_table.ttl"), ("requirements", "fetch_my_pencil_like_my_pen.ttl")],
            (WORLD + "Pencil1", HOME + "isWith", WORLD + "Person"),
            id="another-object-in-an-existing-hierarchy",
        ),
        pytest.param(
            "FetchMyChopstick",
            [("ontology", "chopstick.ttl"), ("map", "chopstick.ttl"), ("requirements", "fetch_my_chopstick.ttl")],
            (WORLD + "Chopstick1", HOME + "isWith", WORLD + "Person"),
            id="a-new-object-class-with-its-shape-and-grasp",
        ),
        pytest.param(
            "MorningRoutine",
            [("ontology", "morning_routine.ttl")],
            (WORLD + "Cup", HOME + "contains", HOME + "Water"),
            id="a-two-level-task",
        ),
    ],
)
def test_a_task_written_only_in_turtle_runs(
    task: str, files: list[tuple[str, str]], fact: tuple[str, str, str]
) -> None:
    kb = knowledge(*files)
    result = run(kb, task)
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert fact in world_facts(kb)
    if task == "MorningRoutine":
        plan = result.composition.plan
        assert plan is not None and plan.method == "decomposed"
        assert (WORLD + "Pen", HOME + "isWith", WORLD + "Person") in world_facts(kb)
        assert {step.part_of for step in plan.steps} >= {
            PREFIXES["act"] + "FindCupOnTable",
            PREFIXES["act"] + "FetchMyPen",
        }  # two levels: ServeACup's own sub-actions, and FetchMyPen
