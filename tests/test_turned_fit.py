"""A footprint that fits its support's top only turned (kb/turned_fit.py): the map's check takes a 40 cm
ruler lying across a 35 x 30 cm tray where its home:yaw is a turn that fits, and the world stands it so;
it refuses it at a turn that does not fit, and one no turn fits; and a carry onto such a top is refused
before anything moves, saying the set-down does not turn things (docs/tasks.md, "What a top holds")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import MapError, SemanticMap
from cbrs.kb.turned_fit import fits_at, fits_some_turn, fits_unturned, fitting_turns, turned_extent
from cbrs.sim.components import SimEnvironment
from cbrs.sim.run_checks import PlaceTooSmallError
from cbrs.sim.world import open_world

LAB = "https://example.org/lab#"
TRAY = "home:minX 7.02 ; home:maxX 7.37 ; home:minY 3.00 ; home:maxY 3.30"  # 35 x 30 cm

# A tray standing on the kitchen table, west of the cup, and a 40 cm ruler: on the tray, turned by YAW,
# or (ON_TABLE) on the table, where ruler.ttl puts its 30 cm one.
MAP = f"""
@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab:   <https://example.org/lab#> .
@prefix owl:   <http://www.w3.org/2002/07/owl#> .
@prefix rdfs:  <http://www.w3.org/2000/01/rdf-schema#> .
lab:Ruler a owl:Class ; rdfs:subClassOf home:PersonalItem ; rdfs:label "ruler"@en ;
    home:graspApproach "top" ; home:graspHeightRatio 0.5 .
lab:Tray a owl:Class ; rdfs:subClassOf home:Furniture , home:ObjectPlace ; rdfs:label "tray"@en .
lab:Tray1 a lab:Tray , owl:NamedIndividual ; rdfs:label "tray on the table"@en ;
    {TRAY} ; home:minZ 0.75 ; home:maxZ 0.77 .
lab:Ruler1 a lab:Ruler , owl:NamedIndividual ; rdfs:label "long ruler"@en ;
    home:shapeKind "box" ; home:sizeX LENGTH ; home:sizeY 0.03 ; home:sizeZ 0.008 ; home:massKg 0.05 ;
    home:colourName "yellow" ; home:rgba "0.95 0.85 0.10 1" ;
    home:isLocatedOn WHERE ; home:yaw YAW .
"""
ON_TRAY = "lab:Tray1 ; home:x 7.195 ; home:y 3.15"
ON_TABLE = "world:KitchenTable ; home:x 7.95 ; home:y 3.12"

TASK = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix svc:  <https://w3id.org/cbrs/service#> .
@prefix lab:  <https://example.org/lab#> .
lab:PutRulerOnTray a cbrs:Requirement ;
    cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ; cbrs:serviceName "PutRulerOnTray" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "ruler" ; cbrs:parameterType lab:Ruler ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "tray" ; cbrs:parameterType lab:Tray ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject lab:Ruler ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject lab:Tray ] ] .
"""


def _kb(tmp_path: Path, where: str = ON_TRAY, yaw: float = 0.68, length: float = 0.40) -> KnowledgeBase:
    path = tmp_path / "ruler_and_tray.ttl"
    text = MAP.replace("WHERE", where).replace("YAW", f"{yaw:g}").replace("LENGTH", f"{length:g}")
    path.write_text(text, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([path], graph="ontology")
    kb.load([path], graph="map")
    return kb


def test_the_closed_form_agrees_with_turning_the_footprint_through_a_quarter_turn() -> None:
    """Random footprints and tops, a third of them long things on smaller tops (where a turn matters):
    whether some turn fits, by the closed form, against the extents at 20001 turns in [0, pi/2]."""
    rng = np.random.default_rng(7)
    turns = np.linspace(0.0, math.pi / 2, 20001)
    c, s = np.cos(turns), np.sin(turns)
    turned_only = 0
    for n in range(400):
        if n % 3 == 0:  # a ruler, a pencil, a spoon across a stool, a tray, a shelf
            top = (float(rng.uniform(0.1, 0.6)), float(rng.uniform(0.1, 0.6)))
            length = float(rng.uniform(max(top), math.hypot(*top)))
            width = float(rng.uniform(0.002, 0.1))
        else:
            length, width = float(rng.uniform(0.01, 1.0)), float(rng.uniform(0.005, 0.5))
            top = (float(rng.uniform(0.05, 1.0)), float(rng.uniform(0.05, 1.0)))
        scanned = bool(np.any((length * c + width * s <= top[0] + 1e-9) & (length * s + width * c <= top[1] + 1e-9)))
        assert fits_some_turn(length, width, top) == scanned, (length, width, top)
        turned_only += scanned and not fits_unturned(length, width, top)
    assert turned_only >= 20  # the case the closed form is for was met, not only the easy ones


def test_the_ruler_across_the_tray_fits_only_within_the_turns_said() -> None:
    assert turned_extent(0.40, 0.03, 0.0) == pytest.approx((0.40, 0.03))
    assert not fits_unturned(0.40, 0.03, (0.35, 0.30)) and fits_some_turn(0.40, 0.03, (0.35, 0.30))
    (low, high), *more = fitting_turns(0.40, 0.03, (0.35, 0.30))
    assert not more and 0.5 < low < high < 0.9
    assert fits_at(0.40, 0.03, (low + high) / 2, (0.35, 0.30)) and fits_at(0.40, 0.03, -(low + high) / 2, (0.35, 0.30))
    assert not fits_at(0.40, 0.03, low - 0.01, (0.35, 0.30)) and not fits_at(0.40, 0.03, high + 0.01, (0.35, 0.30))
    assert not fits_some_turn(0.47, 0.03, (0.35, 0.30))  # longer than the tray's diagonal less its width
    assert not fits_some_turn(0.30, 0.30, (0.29, 0.35))  # a square turned never fits where it did not


def test_the_map_takes_the_ruler_at_a_turn_that_fits_and_refuses_it_at_one_that_does_not(tmp_path: Path) -> None:
    ruler = SemanticMap.read(_kb(tmp_path)).objects[LAB + "Ruler1"]
    assert ruler.start.yaw == pytest.approx(0.68) and ruler.support == LAB + "Tray1"
    with pytest.raises(MapError, match=r"fits it only turned, at home:yaw 0\.\d\d to 0\.\d\d rad") as turned:
        _kb(tmp_path, yaw=0.0)
    assert "its home:yaw is 0" in str(turned.value) and "does not turn it to fit" in str(turned.value)
    with pytest.raises(MapError, match=r"wider than the top of its support Tray1 .*, however turned"):
        _kb(tmp_path, length=0.50)
    with pytest.raises(MapError, match=r"sizes are in metres: 40 cm is 0\.4"):  # fits, turned, in metres
        _kb(tmp_path, length=40.0)


def test_the_world_stands_the_ruler_turned_on_the_tray(tmp_path: Path) -> None:
    """The world builds a thing turned as home:yaw says (and the seed's turn): the ruler rests on the
    tray's top, its centre over the tray, not over its edge and down onto the table."""
    kb = _kb(tmp_path)
    tray = SemanticMap.read(kb).things[LAB + "Tray1"].box
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        world.step(1.0)
        x, y, z = world.pose("Ruler1").position
    assert tray.min_x < x < tray.max_x and tray.min_y < y < tray.max_y
    assert z == pytest.approx(tray.max_z + 0.004, abs=0.002)


def test_a_carry_onto_a_top_the_ruler_fits_only_turned_is_refused_before_anything_moves(tmp_path: Path) -> None:
    """The map may stand it there turned, but the carry sets a thing down turned as it lies in the hand,
    by its circle: refused by the check before the run, saying so, not as out of reach."""
    kb = _kb(tmp_path, where=ON_TABLE, yaw=0.35)
    task = tmp_path / "put_ruler_on_tray.ttl"
    task.write_text(TASK, encoding="utf-8")
    kb.load([task], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        ruler = world.pose("Ruler1").position
        with pytest.raises(PlaceTooSmallError) as refused:
            run_task(kb, "PutRulerOnTray", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.pose("Ruler1").position == pytest.approx(ruler, abs=1e-3)
    said = str(refused.value)
    assert refused.value.place == LAB + "Tray1" and refused.value.top == pytest.approx((0.35, 0.30))
    assert "never turned to fit" in said and "it would fit turned, which the simulation does not do" in said
