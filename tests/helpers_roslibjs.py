"""roslibjs under node for the tests that drive cbrs with it: where the scripts are, and skips saying
what is missing (node >= 20, then ``npm ci --prefix tests/js``)."""

from __future__ import annotations

import json
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import pytest

JS = Path(__file__).parent / "js"
NODE = shutil.which("node")

ROSLIBJS_MARKS = [
    pytest.mark.skipif(NODE is None, reason="node is not installed (roslibjs runs on node >= 20)"),
    pytest.mark.skipif(
        not (JS / "node_modules" / "roslib").is_dir(), reason="roslibjs is not installed: run npm ci --prefix tests/js"
    ),
]

_F = TypeVar("_F", bound=Callable[..., Any])


def needs_roslibjs(test: _F) -> _F:
    """Skip ``test`` where node or roslibjs is missing, saying which."""
    for mark in ROSLIBJS_MARKS:
        test = mark(test)
    return test


def node_command(script: str, *args: object) -> list[str]:
    """The command that runs a script of tests/js with ``args``."""
    assert NODE is not None
    return [NODE, str(JS / script), *map(str, args)]


def node(script: str, *args: object, timeout: float = 60) -> dict[str, Any]:
    """Run a node script of tests/js to its end (killed past ``timeout``); the one line of JSON it prints last."""
    child = subprocess.run(node_command(script, *args), capture_output=True, text=True, timeout=timeout)
    assert child.returncode == 0, child.stderr
    found: dict[str, Any] = json.loads(child.stdout.strip().splitlines()[-1])
    return found


def node_inline(source: str, *args: object, timeout: float = 60) -> dict[str, Any]:
    """Run an ES module given as text in tests/js (its imports resolve there, ``roslib`` too), with
    ``args`` from ``process.argv[1]`` on, as :func:`node` runs a script: the one line of JSON it prints last."""
    assert NODE is not None
    command = [NODE, "--input-type=module", "-e", source, *map(str, args)]
    child = subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=JS)
    assert child.returncode == 0, child.stderr
    found: dict[str, Any] = json.loads(child.stdout.strip().splitlines()[-1])
    return found
