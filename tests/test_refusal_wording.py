"""Two refusals of the tenth round worded for who reads them (docs/tasks.md, "A tenth round"): a misspelt
remote component given to --fail is "no component" (with --bridge, or on a server, the names known include
the components over the bridge), and a served directory opened from Python tells the program to open the
server's URL with remote_token, while the CLI keeps its --store advice."""

from __future__ import annotations

import re
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import SERVED_AT, StoreInUseError
from cbrs.tasks import TaskRunner, UnknownComponentError

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
URL = "http://127.0.0.1:18480"
MISSPELT = "lab10:SwitchOnReadingLamp_LampPlug1"
NEAR = "(did you mean lab10:SwitchOnReadingLamp_LampPlug01 or lab10:SwitchOffReadingLamp_LampPlug01?)"


@pytest.fixture(scope="module")
def lamp_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An on-disk store with the round's lamp, its tasks and its plug registered (closed again)."""
    path = tmp_path_factory.mktemp("lamp") / "store"
    kb = KnowledgeBase.open(path)
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab10_reading_lamp.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab10_switch_on_the_lamp.ttl"], graph="requirements")
    kb.registry.register((EXAMPLES / "lab10_lamp_switch.ttl").read_text(encoding="utf-8"))
    kb.close()
    return path


def _run(store: Path, *args: str) -> str:
    result = CliRunner().invoke(cli, ["--store", str(store), "run", "SwitchOnTheReadingLamp", *args])
    assert result.exit_code == 2, result.output
    return " ".join(result.output.split())


def test_a_misspelt_remote_component_with_a_bridge_is_no_component(lamp_store: Path) -> None:
    """Refused before the bridge is reached (nothing listens on port 9) and before the world is built."""
    said = _run(lamp_store, "--bridge", "ws://127.0.0.1:9", "--fail", MISSPELT)
    assert f"no component {MISSPELT} {NEAR}" in said
    assert "simulated" not in said


def test_without_a_bridge_the_run_can_fail_only_simulated_components(lamp_store: Path) -> None:
    said = _run(lamp_store, "--fail", MISSPELT)
    assert f"no simulated component {MISSPELT}" in said


def test_a_servers_run_calls_it_no_component_and_names_the_near_ones(lamp_store: Path) -> None:
    kb = KnowledgeBase.open(lamp_store)
    try:
        runner = TaskRunner(kb, threading.RLock(), camera=None)
        with pytest.raises(UnknownComponentError) as refused:
            runner.start("SwitchOnTheReadingLamp", faults=[MISSPELT])
    finally:
        kb.close()
    assert str(refused.value) == f"no component {MISSPELT} {NEAR}"
    assert refused.value.names == [MISSPELT]


@pytest.fixture
def served(tmp_path: Path) -> Iterator[Path]:
    """A directory held open by this process, as a running cbrs serve holds it, with the URL it serves at."""
    path = tmp_path / "served"
    kb = KnowledgeBase.open(path, seed=False)
    (path / SERVED_AT).write_text(URL, encoding="utf-8")
    yield path
    kb.close()


def test_a_program_opening_a_served_directory_is_told_to_open_the_url(served: Path) -> None:
    with pytest.raises(StoreInUseError) as refused:
        KnowledgeBase.open(served)
    said = str(refused.value)
    assert refused.value.served == URL and refused.value.location == str(served)
    assert f"KnowledgeBase.open('{URL}', remote_token=...)" in said
    assert "--store" not in said and "CBRS_UPDATE_TOKEN" not in said


def test_the_cli_opening_a_served_directory_keeps_its_own_advice(served: Path) -> None:
    result = CliRunner().invoke(cli, ["--store", str(served), "query", "ASK { ?s ?p ?o }"])
    assert result.exit_code == 1
    said = " ".join(result.output.split())
    assert f"a cbrs server serves it: use --store {URL} (the token from CBRS_UPDATE_TOKEN)" in said
    assert not re.search(r"KnowledgeBase\.open", said)
