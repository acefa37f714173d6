"""A long load tells a person at a terminal how it goes (new-user CLI repro 06: OWLS-TC's half minute
and a 100 MB file's minutes passed without a word), and prints nothing extra anywhere else."""

from __future__ import annotations

import io
from pathlib import Path

from cbrs.kb import KnowledgeBase
from cbrs.output import ProgressLine

DATA = Path(__file__).parent / "data"


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_load_tells_each_stage_and_counts_the_files() -> None:
    kb = KnowledgeBase.open(":memory:")
    told: list[tuple[str, int, int]] = []
    files = sorted((DATA / "owls" / "services").glob("*.owls"))
    kb.load(files, catalogue=DATA / "owls" / "catalog-v001.xml", progress=lambda *step: told.append(step))
    reading = [(done, total) for stage, done, total in told if stage == "reading"]
    assert reading == [(done, len(files)) for done in range(len(files))]
    stages = list(dict.fromkeys(stage.split(" ")[0] for stage, _, _ in told))
    assert stages == ["reading", "converting", "checking", "writing", "updating"]
    written = next(stage for stage, _, _ in told if stage.startswith("writing"))
    assert int(written.split()[1]) > 0


def test_a_terminal_gets_one_line_rewritten_then_cleared() -> None:
    stream = _Terminal()
    line = ProgressLine(stream, interval=0.0)
    line("reading", 3, 10)
    line("checking", 0, 0)
    line.clear()
    assert stream.getvalue() == "\rreading 3/10 ...\rchecking ...    " + "\r" + " " * 12 + "\r"


def test_nothing_when_not_a_terminal() -> None:
    stream = io.StringIO()
    line = ProgressLine(stream, interval=0.0)
    line("reading", 3, 10)
    line.clear()
    assert stream.getvalue() == ""
