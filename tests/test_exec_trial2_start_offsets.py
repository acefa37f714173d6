"""A seed's start offsets of an object do not depend on the other objects of the map (new-user trial 2).
They were drawn from one generator in the order of the objects' names, so an object added to the map
moved every object whose name sorted after it: with two example tasks loaded in one store, a tin started
4 cm away, where it could not be taken. Each object now draws from a generator of its own, seeded by the
seed and its IRI (``Perturbation.of_object``, docs/simulation.md "Determinism")."""

from __future__ import annotations

import pytest

from cbrs.sim.scene import bundled_map
from cbrs.sim.world import Perturbation, Spread

MUG = "https://example.org/lab#AAMug"  # its name sorts before every object of the bundled map


def _bundled() -> dict[str, tuple[str, bool]]:
    return {obj.name: (obj.iri, obj.shape == "cylinder") for obj in bundled_map().objects.values()}


@pytest.mark.parametrize("seed", [0, 1, 7])
def test_adding_or_removing_an_object_leaves_the_other_start_poses_as_they_were(seed: int) -> None:
    objects = _bundled()
    assert len(objects) >= 2
    alone = Perturbation.from_seed(seed, objects)
    with_mug = Perturbation.from_seed(seed, {"AAMug": (MUG, False), **objects})
    first = min(objects)
    without_first = Perturbation.from_seed(seed, {name: v for name, v in objects.items() if name != first})
    assert {name: with_mug.objects[name] for name in objects} == alone.objects
    assert {name: alone.objects[name] for name in without_first.objects} == without_first.objects
    assert (with_mug.person, with_mug.base) == (alone.person, alone.base) == (without_first.person, without_first.base)
    assert with_mug.objects["AAMug"] not in alone.objects.values()


def test_an_objects_offsets_follow_its_iri_and_the_seed_not_its_name_or_the_order() -> None:
    pen = next(obj.iri for obj in bundled_map().objects.values() if obj.shape == "box")
    spread = Spread()
    offsets = Perturbation.of_object(3, pen)
    assert Perturbation.from_seed(3, {"Renamed": (pen, False)}).objects["Renamed"] == offsets
    assert Perturbation.of_object(3, MUG) != offsets != Perturbation.of_object(4, pen)
    dx, dy, dyaw = offsets
    assert abs(dx) <= spread.object and abs(dy) <= spread.object and 0 < abs(dyaw) <= spread.yaw
    assert Perturbation.of_object(3, pen, round_=True) == (dx, dy, 0.0)  # a round object keeps x and y
