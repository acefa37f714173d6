"""Every README block works pasted in order: run here, in a temporary directory, on a store of its own.

Run as written: every `cbrs` line of the usage and task blocks, the error transcript (its output compared
exactly) and the Python block. Left out, each for the reason given in ``SKIPPED``: the quick start (it
installs into a new virtual environment), the blocks that need a running server or a data set that is
not shipped, and the few long commands each covered by its own tests. A `cbrs run` line is checked
through `cbrs plan` of the same task (the same name resolution and composition, without the
simulation; tests/test_run.py runs tasks), and its `--fail COMPONENT` must leave another component
offering that service at that point.
"""

from __future__ import annotations

import json
import os
import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb.namespaces import expand

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"^```(\w*)\n(.*?)^```", README, re.MULTILINE | re.DOTALL)

# Blocks left out, recognised by a phrase in them.
SKIPPED_BLOCKS = {
    "python3 -m venv": "the quick start installs into a new virtual environment (minutes); .ci/run runs it verbatim",
    "owls-tc4/": "needs the OWLS-TC 4 collection, which is not shipped",
    "cbrs serve": "starts long-running servers; tests/test_serve.py and tests/test_serve_clients.py serve them",
    "new ROSLIB.Ros": "needs a running server and roslibjs under node; tests/test_rosbridge_roslibjs.py runs them",
}
# Commands left out (by their first words): long, and each covered by its own tests.
SKIPPED_COMMANDS = {
    "cbrs eval paper": "every method over the 20 x 100 testbed; tests/test_eval_cli.py runs it",
    "cbrs check": "starts Java's HermiT (seconds); tests/test_check.py and tests/test_check_write_back.py run it",
    "cbrs --store :memory: demo": "plans and runs three simulated scenarios; tests/test_cli.py runs the demo",
    "cbrs demo --external": "starts camera programs and kills one mid-run; tests/test_external_demo.py runs it",
}


def _skipped(text: str, table: dict[str, str]) -> str | None:
    return next((reason for phrase, reason in table.items() if phrase in text), None)


def _cbrs(args: list[str]) -> str:
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, f"cbrs {shlex.join(args)} exited {result.exit_code}:\n{result.output}"
    return result.output


WRITES = ("init", "load", "register", "deregister")


class _Runs:
    """`cbrs run TASK [options]` checked as `cbrs plan TASK`: planned once per task while nothing is
    written (a plan takes seconds), and every `--fail` must leave another component with that service."""

    def __init__(self) -> None:
        self.planned: set[str] = set()

    def wrote(self) -> None:
        self.planned.clear()

    def check(self, args: list[str]) -> None:
        task = args[1]
        if task not in self.planned:
            plan = json.loads(_cbrs(["plan", task, "--no-store", "--json"]))
            assert plan["status"] == "planned", plan
            self.planned.add(task)
        for component in (args[i + 1] for i, word in enumerate(args) if word == "--fail"):
            others = _cbrs(["query", "--format", "csv", FAILOVER.replace("COMPONENT", expand(component))])
            assert len(others.splitlines()) > 1, f"nothing to fail over to from {component} at this point"


# Another registered component offering the same service as COMPONENT.
FAILOVER = """SELECT ?other WHERE { <COMPONENT> cbrs:serviceName ?name . ?other cbrs:serviceName ?name ;
  a/rdfs:subClassOf* cbrs:Advertisement . FILTER(?other != <COMPONENT>) }"""


def test_the_readme_blocks_work_pasted_in_order(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    for folder in ("docs", "tests", "ontologies"):  # the example files the README names
        (tmp_path / folder).symlink_to(ROOT / folder)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("CBRS_STORE", str(tmp_path / "store"))
    ran = {"sh": 0, "transcript": 0, "python": 0}
    runs = _Runs()
    for language, body in BLOCKS:
        if _skipped(body, SKIPPED_BLOCKS):
            continue
        if language == "python":
            exec(compile(body, "README.md", "exec"), {})  # its own :memory: store
            ran["python"] += 1
        elif language == "" and body.startswith("$ cbrs "):
            command, _, expected = body.partition("\n")
            result = CliRunner().invoke(cli, shlex.split(command[len("$ cbrs ") :]))
            assert result.exit_code == 1 and result.output == expected, result.output
            ran["transcript"] += 1
        elif language == "sh":
            for line in body.splitlines():
                words = shlex.split(line, comments=True)
                if not words or _skipped(shlex.join(words), SKIPPED_COMMANDS):
                    continue
                assert words[0] == "cbrs", line
                if words[1] == "run":
                    runs.check(words[1:])
                else:
                    _cbrs(words[1:])
                if words[1] in WRITES:
                    runs.wrote()
                ran["sh"] += 1
    assert ran["sh"] >= 20 and ran["transcript"] == 1 and ran["python"] == 1, ran
    assert (tmp_path / "srg.svg").is_file()  # written where the README was pasted
    assert not (ROOT / "srg.svg").exists() or os.path.samefile(tmp_path, ROOT)


def test_every_block_is_run_or_skipped_for_a_stated_reason() -> None:
    languages = {language for language, _ in BLOCKS}
    assert languages <= {"sh", "python", "js", ""}, languages
    for language, body in BLOCKS:
        if language == "js" or (language == "" and not body.startswith("$ cbrs ")):
            assert language == "" or _skipped(body, SKIPPED_BLOCKS), body[:80]
