"""A run's given step takes the requirements that supply a plan's inputs from the composition that made the
plan, as composed moments before, rather than reading each from the store again (one request each to a
remote store: three for RobotArmServeACup's three sub-actions; docs/remote-store.md, "Requests of a
plan and a run")."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cbrs.actions.composer import Composer, CompositionResult
from cbrs.actions.runner import _supplying
from cbrs.kb import KnowledgeBase


@pytest.fixture(scope="module")
def serve_a_cup(bundled_kb: KnowledgeBase) -> CompositionResult:
    result = Composer(bundled_kb).compose("RobotArmServeACup")
    assert result.plan is not None and result.plan.method == "decomposed"
    return result


def _named(composition: CompositionResult) -> set[str]:
    assert composition.plan is not None
    return {
        b.source.requirement
        for step in composition.plan.steps
        for b in step.bindings
        if b.source.step is None and b.source.requirement
    }


def _reads(kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    read: list[str] = []
    description = kb.description

    def counted(iri: str) -> object:
        read.append(iri)
        return description(iri)

    monkeypatch.setattr(kb, "description", counted)
    return read


def test_the_sub_actions_requirements_come_from_the_composition(
    bundled_kb: KnowledgeBase, serve_a_cup: CompositionResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    named = _named(serve_a_cup)
    assert len(named) > 1  # a requirement per sub-action that gives inputs
    read = _reads(bundled_kb, monkeypatch)
    supplied = _supplying(bundled_kb, serve_a_cup)
    assert read == []
    assert set(supplied) == named
    monkeypatch.undo()
    for iri, requirement in supplied.items():
        assert requirement.inputs == bundled_kb.description(iri).inputs  # as the store describes it


def test_a_requirement_the_composition_did_not_attempt_is_read_from_the_store(
    bundled_kb: KnowledgeBase, serve_a_cup: CompositionResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    read = _reads(bundled_kb, monkeypatch)
    supplied = _supplying(bundled_kb, replace(serve_a_cup, attempts=()))
    assert sorted(read) == sorted(_named(serve_a_cup)) == sorted(supplied)
