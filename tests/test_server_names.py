"""A server on a routable address told the names clients reach it by (``server_names``): a request naming
another host is refused as on loopback (DNS rebinding), and its pages under those names may start tasks.
127.0.0.2 stands for the routable address: it is not one of the loopback names, so the server treats it
as it would a lab's address, and the test stays on the loopback interface."""

from __future__ import annotations

from collections.abc import Iterator

import httpx
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.settings import BY_NAME
from cbrs.sparql_service import EndpointConfig
from cbrs.web import host_names

ASK = "ASK { ?s ?p ?o }"


@pytest.fixture(scope="module")
def named() -> Iterator[Server]:
    kb = KnowledgeBase.open(":memory:")
    config = ServeConfig(
        host="127.0.0.2", port=0, bridge_port=0, endpoint=EndpointConfig(timeout=5.0), server_names=("labhost",)
    )
    server = Server(kb, config)
    server.start()
    yield server
    server.stop(timeout=10.0)
    kb.close()


def test_the_names_given_are_answered_and_others_refused(named: Server) -> None:
    port = named.http_port
    url = f"http://127.0.0.2:{port}/sparql"
    with httpx.Client(timeout=10.0) as http:
        by_name = http.get(url, params={"query": ASK}, headers={"Host": f"labhost:{port}"})
        by_address = http.get(url, params={"query": ASK})
        rebound = http.get(url, params={"query": ASK}, headers={"Host": f"evil.example:{port}"})
        page = http.get(f"http://127.0.0.2:{port}/", headers={"Host": f"evil.example:{port}"})
    assert by_name.status_code == 200 and by_address.status_code == 200
    assert rebound.status_code == 421 and "evil.example" in rebound.text and "labhost" in rebound.text
    assert page.status_code == 421


def test_a_page_under_a_given_name_may_start_a_task(named: Server) -> None:
    port = named.http_port
    with httpx.Client(timeout=10.0) as http:
        own = http.post(
            f"http://127.0.0.2:{port}/tasks.json",
            data={"task": "NoSuchTask"},
            headers={"Host": f"labhost:{port}", "Origin": f"http://labhost:{port}"},
        )
        other = http.post(
            f"http://127.0.0.2:{port}/tasks.json",
            data={"task": "NoSuchTask"},
            headers={"Host": f"labhost:{port}", "Origin": f"http://otherhost:{port}"},
        )
    assert own.status_code == 400 and "NoSuchTask" in own.text  # past the gate, to the form
    assert other.status_code == 403


def test_without_names_a_routable_server_answers_any_host() -> None:
    own = frozenset({"http://0.0.0.0:8080", "http://127.0.0.1:8080"})
    assert host_names(own, frozenset()) is None
    names = host_names(own, frozenset(), frozenset({"labhost"}))
    assert names is not None and "labhost" in names and "evil.example" not in names


@pytest.mark.parametrize("text", ["http://labhost", "labhost:8080", "lab host", "-labhost", "lab_host"])
def test_a_name_that_could_never_match_a_request_is_refused(text: str) -> None:
    with pytest.raises(ValueError, match="not a host name"):
        BY_NAME["server_names"].parse(text)


def test_names_are_read_comma_separated_and_lower_case() -> None:
    assert BY_NAME["server_names"].parse("LabHost, cbrs.lab.example.") == ("labhost", "cbrs.lab.example")
