"""The fastest command blocks of docs/ work pasted as written, as README's do (tests/test_readme.py).

Run here: every `cbrs match` line of docs/matchmaking.md's blocks, each on a throw-away store, and
docs/evaluation.md's `python -m cbrs.reasoner.testbed --check`. The other blocks start servers or run the
simulated home; docs/architecture.md ("Tried by a newcomer from the docs") says which were walked by hand.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.reasoner import testbed

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _command_lines(page: str, prefix: str) -> list[list[str]]:
    """The words of each line of `page`'s code blocks that starts with `prefix`, its comment dropped."""
    text = (DOCS / page).read_text(encoding="utf-8")
    blocks = re.findall(r"^```\w*\n(.*?)^```", text, re.MULTILINE | re.DOTALL)
    lines = (line for block in blocks for line in block.splitlines() if line.startswith(prefix))
    return [shlex.split(line, comments=True) for line in lines]


MATCH_LINES = _command_lines("matchmaking.md", "cbrs match ")


def test_matchmaking_md_has_the_match_lines_this_test_runs() -> None:
    assert len(MATCH_LINES) >= 4, MATCH_LINES


@pytest.mark.parametrize("words", MATCH_LINES, ids=shlex.join)
def test_a_match_line_of_matchmaking_md_works_pasted(words: list[str]) -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *words[1:]])
    assert result.exit_code == 0, f"{shlex.join(words)} exited {result.exit_code}:\n{result.output}"
    if "--params" in words:
        assert "complement_weight" in result.output and "0.2" in result.output, result.output
    elif "--explain" in words:  # the paper's worked example: the ceiling camera first, its pairs explained
        assert "#1 svc:LocateMobileRobot_CeilingCamera01" in result.output, result.output
    else:
        assert result.output.startswith("req:RobotSelfPosition: matched by wu-palmer"), result.output


def test_evaluation_md_testbed_check_says_the_committed_files_are_current(capsys: pytest.CaptureFixture[str]) -> None:
    assert ["python", "-m", "cbrs.reasoner.testbed", "--check"] in _command_lines("evaluation.md", "python -m")
    assert testbed.main(["--check"]) == 0
    assert capsys.readouterr().out == "testbed is current\n"
