"""A relation to a quality class is kept in the belief only when it is the subject's own quality, by a
relation of home:hasQualityPart's family ((Door, hasStatus, Opened), (Kettle, hasStatus, SwitchedOn)); an
alert about a door's status ((Person, lab6:isAlertedOf, DoorStatus)) is no lasting state of the person, and
is not kept, as the speaker's inform is not (docs/components.md; docs/tasks.md, "A sixth round"). The run
that shows it is tests/test_blind_tasks6.py's WatchTheFridge; this checks the rule without a world."""

from __future__ import annotations

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.components import SimEnvironment

HOME = PREFIXES["home"]


def test_only_a_quality_of_the_subject_stands_for_itself(bundled_kb: KnowledgeBase) -> None:
    environment = object.__new__(SimEnvironment)  # the rule reads the store alone: no world is built
    environment.kb = bundled_kb
    environment._superclasses, environment._qualities = None, None
    assert environment._own_quality(HOME + "hasStatus", HOME + "Opened")
    assert environment._own_quality(HOME + "hasStatus", HOME + "SwitchedOn")
    assert not environment._own_quality("https://example.org/lab6#isAlertedOf", HOME + "DoorStatus")
    assert not environment._own_quality(HOME + "hasStatus", HOME + "Cup")  # no quality: a thing, grounded so
