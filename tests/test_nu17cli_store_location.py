"""A --store that reads as a server is never made into a new local store (new-user CLI repro 01)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb.errors import StoreError
from cbrs.kb.store import EmbeddedStore


@pytest.mark.parametrize(
    ("location", "says"),
    [
        pytest.param("localhost:7878", "http://localhost:7878", id="host-port"),
        pytest.param("127.0.0.1:7878", "http://127.0.0.1:7878", id="address-port"),
        pytest.param("[::1]:7878/query", "http://[::1]:7878/query", id="ipv6-path"),
        pytest.param("ftp://127.0.0.1:7878", "http:// or https://", id="other-scheme"),
        pytest.param("", "names no store", id="empty"),
        pytest.param("   ", "names no store", id="blank"),
    ],
)
def test_url_like_location_is_refused_and_nothing_is_made(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, location: str, says: str
) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(cli, ["--store", location, "services"])
    assert result.exit_code == 1
    assert says in result.output
    assert list(tmp_path.iterdir()) == []


def test_existing_directory_of_such_a_name_still_opens(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "host:7878").mkdir()
    EmbeddedStore.open("host:7878").close()
    EmbeddedStore.open("./new:7878").close()  # asked for on purpose
    assert (tmp_path / "new:7878").is_dir()
    with pytest.raises(StoreError, match=r"\./other:1"):
        EmbeddedStore.open("other:1")


@pytest.mark.parametrize("location", [None, 7878, b"store"])
def test_a_location_of_another_type_is_refused_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, location: object
) -> None:
    """``KnowledgeBase.open(None)`` made and seeded a store in a directory called ``None``."""
    from cbrs.kb import KnowledgeBase

    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError, match=repr(location)):
        KnowledgeBase.open(location)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
