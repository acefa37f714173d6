"""Programs and rosbridge clients as a new user runs them against a served knowledge base.

rosbridge's fragments and PNG compression, which cbrs refused before: a client may send a message in
``fragment`` pieces (a board with small buffers), and ask for a subscription's messages or a call's
response in pieces of ``fragment_size`` or, for a subscription, as PNG images; roslibjs decodes both.

The README's camera program, started beside a plain ``cbrs serve``, used to end in a traceback: the
store already holds the bundled camera it registers. It now says why in one line and exits 1, as the
CLI does, and once the bundled component makes way it registers.
"""

from __future__ import annotations

import base64
import io
import json
import socket
import subprocess
import time
from collections.abc import Iterator
from typing import Any

import pytest
from websockets.sync.client import ClientConnection, connect

from cbrs import external_camera
from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.rosbridge.wire import MAX_PARTIAL, MAX_PIECES, MIN_FRAGMENT
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.helpers_roslibjs import JS, NODE, needs_roslibjs

TOKEN = "clients-bridge-token"
WAIT = 10.0


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    served = Server(
        KnowledgeBase.open(":memory:"),
        ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)),
    )
    served.start()
    yield served
    served.stop(timeout=WAIT)


def _closed_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_the_camera_program_without_a_server_says_so_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    url = f"ws://127.0.0.1:{_closed_port()}"
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Error: CeilingCamera01: cannot reach the bridge") and err.count("\n") == 1, err


def test_the_camera_program_refused_says_why_in_one_line(
    server: Server, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    url = f"ws://127.0.0.1:{server.bridge_port}"
    monkeypatch.delenv("CBRS_UPDATE_TOKEN", raising=False)
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert "needs the update token" in err and err.count("\n") == 1, err
    monkeypatch.setenv("CBRS_UPDATE_TOKEN", TOKEN)
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert "LocateMobileRobot_CeilingCamera01> is a component of the store, not a live one" in err, err
    assert err.count("\n") == 1, err


# -- rosbridge's fragments and PNG compression ------------------------------------------------------


@pytest.fixture
def bridge() -> Iterator[RunningBridge]:
    served = Bridge(max_message_bytes=64 * 1024)
    served.add_service("/test/big", "test/Big", lambda args: {"text": "y" * args.get("n", 3000)})
    with served.start(port=0) as running:
        yield running


def receive_all(ws: ClientConnection, quiet: float = 0.3) -> list[dict[str, Any]]:
    """Every message that arrives until none has for ``quiet`` seconds (bounded: the test's clients are few)."""
    got: list[dict[str, Any]] = []
    while len(got) < 1000:
        try:
            got.append(json.loads(ws.recv(timeout=quiet)))
        except TimeoutError:
            break
    return got


def joined(pieces: list[dict[str, Any]]) -> dict[str, Any]:
    assert all(piece["op"] == "fragment" for piece in pieces), pieces
    assert [piece["num"] for piece in pieces] == list(range(pieces[0]["total"]))
    assert len({piece["id"] for piece in pieces}) == 1
    whole: dict[str, Any] = json.loads("".join(piece["data"] for piece in pieces))
    return whole


def test_a_message_sent_in_pieces_in_any_order_is_acted_on(bridge: RunningBridge) -> None:
    with connect(bridge.url, open_timeout=WAIT) as ws:
        text = json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t1"})
        pieces = [text[at : at + 10] for at in range(0, len(text), 10)]
        for num in reversed(range(len(pieces))):
            ws.send(json.dumps({"op": "fragment", "id": "m1", "data": pieces[num], "num": num, "total": len(pieces)}))
        (answer,) = receive_all(ws)
    assert answer["op"] == "service_response" and answer["id"] == "t1" and answer["result"] is True


@pytest.mark.parametrize(
    ("pieces", "said"),
    [
        ([{"data": "{", "num": 0, "total": 2}], "a fragment needs the 'id'"),
        ([{"id": "a", "data": "{", "num": 2, "total": 2}], "num must be from 0 to total - 1, not 2 of 2"),
        (
            [{"id": "a", "data": "{", "num": 0, "total": 2}, {"id": "a", "data": "}", "num": 1, "total": 3}],
            "total 3 differs",
        ),
        (
            [{"id": "a", "data": "x" * 40_000, "num": 0, "total": 2}] * 1
            + [{"id": "a", "data": "x" * 40_000, "num": 1, "total": 2}],
            "exceed the limit",
        ),
        (
            [{"id": "a", "data": '{"op":"fragment","id":"b","data":"{}","num":0,"total":1}', "num": 0, "total": 1}],
            "must not be a fragment again",
        ),
        ([{"id": "a", "data": '{"op": "publish"', "num": 0, "total": 1}], "message is not valid JSON"),
        ([{"id": "a", "data": 3, "num": 0, "total": 1}], "field 'data' must be a string"),
    ],
)
def test_pieces_that_cannot_belong_get_a_status_and_the_connection_stays(
    bridge: RunningBridge, pieces: list[dict[str, Any]], said: str
) -> None:
    with connect(bridge.url, open_timeout=WAIT, max_size=None) as ws:
        for piece in pieces:
            ws.send(json.dumps({"op": "fragment", **piece}))
        statuses = [m for m in receive_all(ws) if m["op"] == "status"]
        assert statuses and statuses[-1]["level"] == "error" and said in statuses[-1]["msg"], statuses
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "after"}))
        assert receive_all(ws)[-1]["id"] == "after"


def test_a_piece_sent_twice_is_a_warning_and_the_first_is_kept(bridge: RunningBridge) -> None:
    text = json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "twice"})
    with connect(bridge.url, open_timeout=WAIT) as ws:
        ws.send(json.dumps({"op": "set_level", "level": "warning"}))
        first = {"op": "fragment", "id": "m", "data": text[:20], "num": 0, "total": 2}
        ws.send(json.dumps(first))
        ws.send(json.dumps({**first, "data": "garbage"}))
        ws.send(json.dumps({"op": "fragment", "id": "m", "data": text[20:], "num": 1, "total": 2}))
        got = receive_all(ws)
    assert got[0]["level"] == "warning" and "came twice" in got[0]["msg"]
    assert got[-1]["op"] == "service_response" and got[-1]["id"] == "twice"


def test_a_client_holds_a_bounded_number_of_unfinished_messages(bridge: RunningBridge) -> None:
    with connect(bridge.url, open_timeout=WAIT) as ws:
        ws.send(json.dumps({"op": "set_level", "level": "warning"}))
        for index in range(MAX_PARTIAL + 1):
            ws.send(json.dumps({"op": "fragment", "id": f"never{index}", "data": "{", "num": 0, "total": 2}))
        (warning,) = receive_all(ws)
    assert warning["msg"] == "fragment: dropped the unfinished fragments of 'never0' to make room"


def test_a_stale_unfinished_message_makes_way_for_a_new_one(bridge: RunningBridge) -> None:
    text = json.dumps(
        {"op": "call_service", "service": "/rosapi/get_time", "id": "fresh", "args": {"pad": "x" * 30_000}}
    )
    with connect(bridge.url, open_timeout=WAIT) as ws:  # the bridge's max_message_bytes: 64 KiB
        ws.send(json.dumps({"op": "set_level", "level": "warning"}))
        ws.send(json.dumps({"op": "fragment", "id": "stale", "data": "{" + " " * 40_000, "num": 0, "total": 2}))
        for num, at in enumerate(range(0, len(text), 20_000)):
            ws.send(json.dumps({"op": "fragment", "id": "new", "data": text[at : at + 20_000], "num": num, "total": 2}))
        warning, answer = receive_all(ws)
        assert warning["msg"] == "fragment: dropped the unfinished fragments of 'stale' to make room"
        assert answer["op"] == "service_response" and answer["id"] == "fresh"
        ws.send(json.dumps({"op": "fragment", "id": "tiny", "data": "{", "num": 0, "total": 64 * 1024}))
        (refused,) = receive_all(ws)
        assert refused["level"] == "error" and "more pieces than a message may have (1024)" in refused["msg"]


def test_subscriptions_and_calls_in_pieces_of_fragment_size(bridge: RunningBridge) -> None:
    with connect(bridge.url, open_timeout=WAIT) as publisher, connect(bridge.url, open_timeout=WAIT) as reader:
        reader.send(json.dumps({"op": "set_level", "level": "warning"}))
        reader.send(json.dumps({"op": "subscribe", "topic": "/big", "type": "t/T", "fragment_size": 10, "id": "s"}))
        (raised,) = receive_all(reader)
        assert raised["msg"] == f"fragment_size 10 raised to {MIN_FRAGMENT}" and raised["id"] == "s"
        publisher.send(json.dumps({"op": "advertise", "topic": "/big", "type": "t/T"}))
        publisher.send(json.dumps({"op": "publish", "topic": "/big", "msg": {"data": "z" * 700}}))
        publisher.send(json.dumps({"op": "publish", "topic": "/big", "msg": {"data": "small"}}))
        got = receive_all(reader)
        assert len(got) == 4 and got[0]["total"] == 3  # 3 pieces of at most 256 characters, then the small one whole
        assert joined(got[:3]) == {"op": "publish", "topic": "/big", "msg": {"data": "z" * 700}}
        assert got[3] == {"op": "publish", "topic": "/big", "msg": {"data": "small"}}
        reader.send(json.dumps({"op": "call_service", "service": "/test/big", "id": "c1", "fragment_size": 1000}))
        pieces = receive_all(reader)
        assert [piece["id"] for piece in pieces] == ["c1"] * 4
        response = joined(pieces)
        assert (
            response["op"] == "service_response" and response["id"] == "c1" and response["values"]["text"] == "y" * 3000
        )
        reader.send(json.dumps({"op": "call_service", "service": "/test/big", "args": {"n": 3}, "fragment_size": 1000}))
        (whole,) = receive_all(reader)  # it fits: sent whole
        assert whole["values"] == {"text": "yyy"}


def test_a_subscription_with_png_compression_gets_rosbridge_png_messages(bridge: RunningBridge) -> None:
    image = pytest.importorskip("PIL.Image")
    message = {"data": "é ☃ " * 40, "n": [1, 2.5, None]}
    with connect(bridge.url, open_timeout=WAIT) as publisher, connect(bridge.url, open_timeout=WAIT) as reader:
        reader.send(json.dumps({"op": "subscribe", "topic": "/img", "type": "t/T", "compression": "png"}))
        publisher.send(json.dumps({"op": "advertise", "topic": "/img", "type": "t/T"}))
        time.sleep(0.1)
        publisher.send(json.dumps({"op": "publish", "topic": "/img", "msg": message}))
        (png,) = receive_all(reader)
    assert set(png) == {"op", "data"} and png["op"] == "png"
    decoded = image.open(io.BytesIO(base64.b64decode(png["data"])), formats=("png",))
    assert decoded.mode == "RGB"  # rosbridge_suite's decode: the pixels' bytes, newlines stripped
    assert json.loads(decoded.tobytes().decode("utf-8")) == {"op": "publish", "topic": "/img", "msg": message}


ROSLIBJS = """
import { Ros, Topic } from "roslib";
setTimeout(() => { console.error("gave up"); process.exit(2); }, 20000).unref();
const url = process.argv[1];
const open = () => new Promise((resolve, reject) => {
  const ros = new Ros({ url });
  ros.on("connection", () => resolve(ros));
  ros.on("error", reject);
});
const [a, b] = [await open(), await open()];
const heard = { png: [], pieces: [] };
new Topic({ ros: b, name: "/img", messageType: "t/T", compression: "png" }).subscribe((m) => heard.png.push(m));
b.callOnConnection({ op: "subscribe", id: "s", topic: "/big", type: "t/T", fragment_size: 300 });
b.on("/big", (m) => heard.pieces.push(m.msg ?? m));  // roslibjs emits the publish message
await new Promise((resolve) => setTimeout(resolve, 300));
const img = new Topic({ ros: a, name: "/img", messageType: "t/T" });
const big = new Topic({ ros: a, name: "/big", messageType: "t/T" });
img.publish({ data: "snow ☃", n: 1 });
big.publish({ data: "z".repeat(2000) });
const deadline = Date.now() + 5000;
while ((heard.png.length < 1 || heard.pieces.length < 1) && Date.now() < deadline) {
  await new Promise((resolve) => setTimeout(resolve, 50));
}
const publishers = await new Promise((resolve, reject) => big.getPublishers(resolve, reject));
console.log(JSON.stringify({ png: heard.png, sizes: heard.pieces.map((m) => m.data.length), publishers }));
process.exit(0);
"""


@needs_roslibjs
def test_roslibjs_decodes_png_and_fragments_from_the_bridge(bridge: RunningBridge) -> None:
    assert NODE is not None
    child = subprocess.run(
        [NODE, "--input-type=module", "-e", ROSLIBJS, bridge.url],
        cwd=JS,  # where "roslib" resolves
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert child.returncode == 0, child.stderr
    found = json.loads(child.stdout.strip().splitlines()[-1])
    assert found == {"png": [{"data": "snow ☃", "n": 1}], "sizes": [2000], "publishers": ["/cbrs_rosbridge"]}


def test_rosapi_names_the_bridge_as_the_node_at_either_end_of_a_clients_topic(bridge: RunningBridge) -> None:
    def rosapi(ws: ClientConnection, service: str, **args: str) -> dict[str, Any]:
        ws.send(json.dumps({"op": "call_service", "service": f"/rosapi/{service}", "args": args, "id": service}))
        answer: dict[str, Any] = json.loads(ws.recv(timeout=WAIT))
        assert answer["result"] is True and answer["id"] == service, answer
        return dict(answer["values"])

    with connect(bridge.url, open_timeout=WAIT) as talker, connect(bridge.url, open_timeout=WAIT) as listener:
        talker.send(json.dumps({"op": "advertise", "topic": "/chatter", "type": "std_msgs/String"}))
        listener.send(json.dumps({"op": "subscribe", "topic": "/heard", "type": "std_msgs/String"}))
        time.sleep(0.1)
        assert rosapi(talker, "publishers", topic="/chatter") == {"publishers": ["/cbrs_rosbridge"]}
        assert rosapi(talker, "publishers", topic="heard") == {"publishers": []}
        assert rosapi(talker, "subscribers", topic="heard") == {"subscribers": ["/cbrs_rosbridge"]}
        assert rosapi(talker, "subscribers", topic="/nobody") == {"subscribers": []}
        details = rosapi(talker, "node_details", node="/cbrs_rosbridge")
        assert details["publishing"] == ["/chatter"] and details["subscribing"] == ["/heard"]


def test_cbrs_match_takes_a_bare_requirement_name_as_the_bridge_does() -> None:
    from click.testing import CliRunner

    from cbrs.cli import cli

    bare = CliRunner().invoke(cli, ["--store", ":memory:", "match", "RobotSelfPosition", "--top", "1", "--json"])
    assert bare.exit_code == 0, bare.output
    assert json.loads(bare.output)["requirement"] == "https://w3id.org/cbrs/requirement#RobotSelfPosition"


def test_a_long_response_is_cut_in_at_most_max_pieces(bridge: RunningBridge) -> None:
    """3 MB in pieces of 256 would be 11,719 replies, past the 10,000 a client may leave unread: the
    pieces grow instead, and the client stays connected."""
    with connect(bridge.url, open_timeout=WAIT) as ws:
        call = {"op": "call_service", "service": "/test/big", "id": "long", "args": {"n": 3_000_000}}
        ws.send(json.dumps({**call, "fragment_size": 256}))
        first = json.loads(ws.recv(timeout=WAIT))
        assert MAX_PIECES - 10 < first["total"] <= MAX_PIECES and len(first["data"]) > 256
        pieces = [first, *(json.loads(ws.recv(timeout=WAIT)) for _ in range(first["total"] - 1))]
        assert joined(pieces)["values"]["text"] == "y" * 3_000_000
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "after"}))
        assert json.loads(ws.recv(timeout=WAIT))["id"] == "after"


def _call(ws: ClientConnection, service: str, args: dict[str, Any]) -> dict[str, Any]:
    ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": service}))
    while True:  # status messages (a log level's) may come first: bounded by the timeout of each recv
        answer: dict[str, Any] = json.loads(ws.recv(timeout=WAIT))
        if answer.get("op") == "service_response" and answer.get("id") == service:
            return answer


def _examples(typedef: dict[str, Any]) -> dict[str, Any]:
    """A request as a form built from a typedef sends it untouched: every field at its example (default)."""
    zero = {"": "", "0": 0, "0.0": 0.0, "False": False, "[]": [], "{}": {}}
    return {name: zero[example] for name, example in zip(typedef["fieldnames"], typedef["examples"], strict=True)}


def test_rosapi_describes_the_knowledge_base_services_and_topics(server: Server) -> None:
    from cbrs.bridge_services import SERVICES, TOPICS
    from tests.test_rosapi_typedefs import cbrs_types

    types = cbrs_types()
    with connect(f"ws://127.0.0.1:{server.bridge_port}", open_timeout=WAIT) as ws:
        for service, kind in SERVICES.items():
            assert _call(ws, "/rosapi/service_type", {"service": service})["values"] == {"type": kind}
            assert service in _call(ws, "/rosapi/services_for_type", {"type": kind})["values"]["services"]
            request = _call(ws, "/rosapi/service_request_details", {"type": kind})["values"]["typedefs"]
            response = _call(ws, "/rosapi/service_response_details", {"type": kind})["values"]["typedefs"]
            assert request == types.request(kind) and request[0]["type"] == kind + "Request"
            assert response == types.response(kind) and response[0]["type"] == kind + "Response"
        listed = _call(ws, "/rosapi/services", {})["values"]["services"]
        for service in listed:  # every cbrs type the server offers, the live components' too
            kind = _call(ws, "/rosapi/service_type", {"service": service})["values"]["type"]
            if kind.startswith("cbrs/"):
                assert types.request(kind) and types.response(kind), f"{service}: {kind} has no definition"
        assert {"/cbrs/register", "/cbrs/heartbeat"} <= set(listed)
        raw = _call(ws, "/rosapi/topics_and_raw_types", {})["values"]
        texts = dict(zip(raw["topics"], raw["typedefs_full_text"], strict=True))
        for topic, kind in TOPICS.items():
            details = _call(ws, "/rosapi/message_details", {"type": kind})["values"]["typedefs"]
            assert details[0]["type"] == kind and details == types.message(kind)
            assert texts[topic] == types.full_text(kind) != ""
        assert texts["/rosout"].startswith("# /rosout")
        assert _call(ws, "/rosapi/message_details", {"type": "cbrs/NoSuch"})["values"] == {"typedefs": []}


def test_the_services_answer_what_their_definitions_say(server: Server) -> None:
    """Each reply's fields are its response definition's, recursively; a request built from the request
    definition's defaults (what a typedef-driven form sends) is accepted."""
    from tests.test_rosapi_typedefs import cbrs_types, mismatches

    types = cbrs_types()
    calls = [
        ("cbrs/Query", "/cbrs/query", {"query": "SELECT ?s WHERE { ?s a ?c } LIMIT 2"}),
        ("cbrs/Query", "/cbrs/query", {"query": "CONSTRUCT WHERE { ?s a ?c } LIMIT 2"}),
        ("cbrs/Match", "/cbrs/match", {"requirement": "RobotSelfPosition", "top": 3}),
        ("cbrs/Match", "/cbrs/match", {"requirement": "RobotSelfPosition"}),
        ("cbrs/Plan", "/cbrs/plan", {"task": "FetchMyPen"}),
        ("cbrs/Plan", "/cbrs/plan", {"task": "RouteToGoal"}),  # unsolvable in the bundled store
        ("cbrs/Tasks", "/cbrs/tasks", {}),
    ]
    replies = []
    with connect(f"ws://127.0.0.1:{server.bridge_port}", open_timeout=WAIT) as ws:
        for kind, service, args in calls:
            answer = _call(ws, service, args)
            assert answer["result"] is True, answer
            assert mismatches(types.response(kind), answer["values"], service) == []
            replies.append(answer["values"])
            as_a_form = {**_examples(types.request(kind)[0]), **args}
            again = _call(ws, service, as_a_form)
            assert again["result"] is True, (as_a_form, again)
    planned, unsolvable = replies[4], replies[5]  # both branches of a plan's reply were checked
    assert planned["status"] == "planned" and planned["steps"] and unsolvable["status"] == "unsolvable"
    assert replies[2]["candidates"][0]["pairs"]  # explained candidates: their pairs were checked too


@needs_roslibjs
def test_roslibjs_reads_and_decodes_the_typedefs_and_calls_with_a_form_built_from_them(server: Server) -> None:
    from tests.test_rosapi_typedefs import cbrs_types

    types = cbrs_types()
    assert NODE is not None
    child = subprocess.run(
        [NODE, str(JS / "typedefs.mjs"), str(server.bridge_port)], capture_output=True, text=True, timeout=60
    )
    assert child.returncode == 0, child.stderr
    found = json.loads(child.stdout.strip().splitlines()[-1])
    assert found["request"] == types.request("cbrs/Match") and found["response"] == types.response("cbrs/Match")
    assert found["progress"] == types.message("cbrs/TaskProgress")
    assert found["decodedRequest"] == {"requirement": "string", "method": "string", "top": "int32"}
    candidate = found["decodedResponse"]["candidates"][0]
    assert candidate["pairs"][0]["similarity"] == "float64" and candidate["parts"] == {}  # cbrs/Json: no fields
    assert found["decodedProgress"]["avoiding"] == ["string"]
    assert found["form"] == {"requirement": "RobotSelfPosition", "method": "", "top": 0}
    assert found["ranked"] == 10  # method "" and top 0, a form's defaults, mean the service's defaults
