"""rosapi's typedefs of cbrs's own types, read from ``cbrs/interfaces`` (``.msg``/``.srv`` files).

rosapi's ``message_details``, ``service_request_details`` and ``service_response_details`` answered empty
typedefs for every cbrs type, so tools that build forms or decoders from them (Foxglove, rqt-like
pages) had nothing. These tests pin the format (ROS 1 rosapi's), the parser's errors, and that the
definitions say what the services read and answer (:func:`mismatches`, also used on live replies in
``tests/test_clients_bridge.py`` and ``tests/test_serve.py``).
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import pytest

from cbrs.bridge_services import FIELDS, INTERFACES, SERVICES, TOPICS
from cbrs.rosbridge import Bridge
from cbrs.rosbridge.interfaces import InterfaceError, Interfaces, parse
from cbrs.rosbridge.rosout import RosoutHandler
from cbrs.tasks import TaskRun

ROOT = Path(__file__).resolve().parents[1]
_INTS = {"byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}


def cbrs_types() -> Interfaces:
    found = Interfaces()
    found.load(INTERFACES, "cbrs")
    return found


def mismatches(typedefs: list[dict[str, Any]], value: Any, where: str = "") -> list[str]:
    """What in ``value`` (a message as JSON) its typedefs (the first is its own) do not describe: a key
    that is no field, or a value of another type. Absent fields and nulls are allowed (the bridge omits
    what does not apply); ``cbrs/Json`` holds anything."""
    by_type = {typedef["type"]: typedef for typedef in typedefs}
    return _check(by_type, typedefs[0]["type"], value, where or typedefs[0]["type"])


def _check(by_type: dict[str, dict[str, Any]], kind: str, value: Any, where: str) -> list[str]:
    if value is None or kind == "cbrs/Json":
        return []
    if kind in by_type:
        if not isinstance(value, dict):
            return [f"{where}: {kind} must be an object, not {value!r}"]
        typedef = by_type[kind]
        fields = dict(
            zip(typedef["fieldnames"], zip(typedef["fieldtypes"], typedef["fieldarraylen"], strict=True), strict=True)
        )
        found = [f"{where}: {kind} has no field {key!r}" for key in value if key not in fields]
        for key, item in value.items():
            if key in fields:
                field_type, array = fields[key]
                found += _field(by_type, field_type, array, item, f"{where}.{key}")
        return found
    return [] if _primitive(kind, value) else [f"{where}: {value!r} is no {kind}"]


def _field(by_type: dict[str, dict[str, Any]], kind: str, array: int, value: Any, where: str) -> list[str]:
    if array < 0:
        return _check(by_type, kind, value, where)
    if not isinstance(value, list):
        return [f"{where}: an array of {kind} must be a list, not {value!r}"]
    return [problem for n, item in enumerate(value) for problem in _check(by_type, kind, item, f"{where}[{n}]")]


def _primitive(kind: str, value: Any) -> bool:
    if kind == "bool":
        return isinstance(value, bool)
    if kind in _INTS:
        return isinstance(value, int) and not isinstance(value, bool)
    if kind.startswith("float"):
        return isinstance(value, int | float) and not isinstance(value, bool)
    return isinstance(value, str) if kind == "string" else isinstance(value, dict)  # time, duration


# -- the format ---------------------------------------------------------------------------------------


def test_a_service_is_described_as_ros_1_rosapi_describes_it() -> None:
    types = cbrs_types()
    assert types.request("cbrs/Match") == [
        {
            "type": "cbrs/MatchRequest",
            "fieldnames": ["requirement", "method", "top"],
            "fieldtypes": ["string", "string", "int32"],
            "fieldarraylen": [-1, -1, -1],
            "examples": ["", "", "0"],
            "constnames": [],
            "constvalues": [],
        }
    ]
    response = types.response("cbrs/Match")
    assert [t["type"] for t in response] == ["cbrs/MatchResponse", "cbrs/Candidate", "cbrs/Json", "cbrs/EntityPair"]
    match, candidate = response[0], response[1]
    assert match["constnames"] == ["MATCHED", "NO_ACCEPTABLE_MATCH"]  # by name, as rosapi lists them
    assert match["constvalues"] == ["matched", "no-acceptable-match"]
    at = candidate["fieldnames"].index("pairs")
    assert (candidate["fieldtypes"][at], candidate["fieldarraylen"][at], candidate["examples"][at]) == (
        "cbrs/EntityPair",
        0,
        "[]",
    )
    assert candidate["examples"][candidate["fieldnames"].index("acceptable")] == "False"
    assert types.request("cbrs/srv/Match") == types.request("cbrs/Match")  # ROS 2's spelling


def test_parse_reads_arrays_constants_comments_and_headers() -> None:
    text = """# a comment line
int32 A=7   # a number's comment is not its value
string S= keep # this too
float64[3] xyz
Header header
other_pkg/Thing[] things  # a comment
time at
"""
    typedef = parse("pkg", "M", text).typedef()
    assert typedef["fieldnames"] == ["xyz", "header", "things", "at"]
    assert typedef["fieldtypes"] == ["float64", "std_msgs/Header", "other_pkg/Thing", "time"]
    assert typedef["fieldarraylen"] == [3, -1, 0, -1]
    assert typedef["examples"] == ["[]", "{}", "[]", "{}"]
    assert (typedef["constnames"], typedef["constvalues"]) == (["A", "S"], ["7", "keep # this too"])


@pytest.mark.parametrize(
    ("line", "reason"),
    [
        pytest.param("int32", "a line is", id="no-name"),
        pytest.param("int32 2x", "no field name", id="bad-name"),
        pytest.param("int32 x\nstring x", "defined twice", id="twice"),
        pytest.param("Thing X=1", "must be a primitive", id="constant-of-a-message"),
        pytest.param("int32 X=seven", "no int32 value", id="constant-value"),
        pytest.param("int32[x] y", "no type", id="array-size"),
    ],
)
def test_a_bad_definition_names_its_file_and_line(line: str, reason: str) -> None:
    with pytest.raises(InterfaceError, match=reason) as caught:
        parse("pkg", "M", line, "pkg/msg/M.msg")
    assert caught.value.source == "pkg/msg/M.msg" and caught.value.line in line


def test_a_load_that_fails_adds_nothing(tmp_path: Path) -> None:
    (tmp_path / "msg").mkdir()
    (tmp_path / "srv").mkdir()
    (tmp_path / "msg" / "Good.msg").write_text("string name\n")
    (tmp_path / "srv" / "Uses.srv").write_text("Missing thing\n---\nbool ok\n")
    types = Interfaces()
    with pytest.raises(InterfaceError, match="'pkg/Missing' is not defined"):
        types.load(tmp_path, "pkg")
    assert types.message("pkg/Good") == [] and types.request("pkg/Uses") == []
    (tmp_path / "srv" / "Uses.srv").write_text("Good thing\nbool ok\n")  # no ---
    with pytest.raises(InterfaceError, match="one '---' line"):
        types.load(tmp_path, "pkg")


def test_rosout_is_described_with_its_header_and_time() -> None:
    bridge = Bridge()
    RosoutHandler(bridge)
    log = bridge.interfaces.message("rosgraph_msgs/Log")
    assert [t["type"] for t in log] == ["rosgraph_msgs/Log", "std_msgs/Header", "time"]
    assert log[0]["constnames"] == ["DEBUG", "ERROR", "FATAL", "INFO", "WARN"]
    assert log[0]["constvalues"] == ["1", "8", "16", "2", "4"]
    assert log[2]["fieldnames"] == ["secs", "nsecs"]
    text = bridge.interfaces.full_text("rosgraph_msgs/Log")
    assert text.startswith("# /rosout") and "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" in text
    record = {"header": {"stamp": {"secs": 1, "nsecs": 2}}, "level": 2, "name": "cbrs", "msg": "hi"}
    assert mismatches(log, {**record, "file": "x.py", "function": "f", "line": 3, "topics": []}) == []


def test_an_unknown_type_has_no_typedef() -> None:
    types = cbrs_types()
    assert types.message("cbrs/NoSuch") == [] and types.request("cbrs/NoSuch") == [] and types.full_text("x/Y") == ""


# -- the definitions say what the services read and answer -----------------------------------------------


def test_every_service_and_topic_type_is_defined_with_the_fields_its_service_reads() -> None:
    types = cbrs_types()
    assert set(SERVICES) == set(FIELDS)
    for service, kind in SERVICES.items():
        request = types.request(kind)
        assert request, f"{kind} ({service}) has no definition"
        assert tuple(request[0]["fieldnames"]) == FIELDS[service], service
        assert types.response(kind), kind
    for topic, kind in TOPICS.items():
        assert types.message(kind), f"{kind} ({topic}) has no definition"


def test_the_live_component_services_read_what_their_definitions_say() -> None:
    from cbrs.live_components import REGISTER_FIELDS

    types = cbrs_types()  # their replies are checked in tests/test_live_components.py
    assert tuple(types.request("cbrs/Register")[0]["fieldnames"]) == REGISTER_FIELDS
    assert types.request("cbrs/Heartbeat")[0]["fieldnames"] == []


def test_a_camera_frame_is_what_its_definition_says() -> None:
    pytest.importorskip("pybullet")
    import numpy as np

    from cbrs.sim.cameras import Frame, Intrinsics
    from cbrs.sim_sensors import frame_to_json

    frame = Frame(
        "Ceiling",
        1.5,
        np.zeros((2, 3, 3), np.uint8),
        np.zeros((2, 3), np.float32),
        Intrinsics(3, 2, 1.0, 1.0, 1.5, 1.0),
        np.eye(4),
    )
    described = cbrs_types().response("cbrs/CaptureFrame")
    assert mismatches(described, frame_to_json(frame)) == []
    assert described[0]["fieldarraylen"][described[0]["fieldnames"].index("camera_to_world")] == len(
        frame_to_json(frame)["camera_to_world"]
    )


def test_a_run_as_the_services_answer_it_is_what_the_definitions_say() -> None:
    types = cbrs_types()
    run = TaskRun("run-1", "FetchMyPen", 3, ("svc:Arm",), 0.1, 2, "urn:x", "failed", 1.0, 2.0)
    run.error, run.result = "it broke", {"execution": {"status": "failed"}}
    run.events.append({"topic": "/cbrs/task", "task": "urn:x", "status": "failed"})
    assert mismatches(types.response("cbrs/RunTask"), run.to_dict(with_events=False)) == []
    assert mismatches(types.response("cbrs/TaskStatus"), run.to_dict()) == []
    assert mismatches(types.response("cbrs/RunTask"), run.to_dict()) == [
        "cbrs/RunTaskResponse: cbrs/RunTaskResponse has no field 'events'"
    ]


def test_the_definitions_ship_in_the_wheel() -> None:
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    shipped = set()
    for package, patterns in setuptools["package-data"].items():
        folder = ROOT / package.replace(".", "/")
        shipped |= {path for pattern in patterns for path in folder.glob(pattern)}
    definitions = [
        *(ROOT / "cbrs" / "interfaces").rglob("*.*"),
        *(ROOT / "cbrs" / "rosbridge" / "definitions").rglob("*.*"),
    ]
    assert len(definitions) > len(SERVICES) + len(TOPICS)
    missing = [str(path.relative_to(ROOT)) for path in definitions if path not in shipped]
    assert not missing, f"not in pyproject.toml's package-data: {missing}"
