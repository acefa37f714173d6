"""The rosapi services, answered by the bridge itself from its graph and parameter store.

Requests and responses follow the rosapi service types of ROS 1 (``rosapi/Topics`` and so on). Parameter
values travel as JSON-encoded strings, as roslibpy and roslibjs send them; ``get_param`` also answers
the ROS 2 fields ``successful`` and ``reason``, which roslibjs reads when present. A value's NaNs and
infinities are written as the bridge's ``non_finite`` says: roslibjs parses the value with JSON.parse too.
``set_param`` reads ``NaN``, ``Infinity`` and ``-Infinity`` (Python's json, what roslibpy writes).
"""

from __future__ import annotations

import json
import time
from typing import Any

from cbrs.rosbridge.errors import ServiceError
from cbrs.rosbridge.graph import Graph, Handler
from cbrs.rosbridge.interfaces import Interfaces
from cbrs.rosbridge.params import ParamStore
from cbrs.rosbridge.protocol import finite, json_type, same_type

#: What ``/rosapi/get_ros_version`` answers: the bridge speaks rosbridge_suite's ROS 2 protocol.
ROS_VERSION = 2

#: The node names rosapi reports: the bridge and rosapi itself.
NODES = ["/cbrs_rosbridge", "/rosapi"]


def _text(args: dict[str, Any], name: str, default: str | None = None) -> str:
    value = args.get(name, default)
    if value is None:
        raise ServiceError(f"missing field {name!r}")
    if not isinstance(value, str):
        raise ServiceError(f"field {name!r} must be a string, not {json_type(value)}")
    return value


def _global(name: str) -> str:
    return name if name.startswith("/") else "/" + name


def _decoded(text: str, what: str) -> Any:
    try:
        return json.loads(text)
    except RecursionError:
        raise ServiceError(f"{what} is nested too deeply to parse ({len(text)} characters)") from None
    except ValueError:
        shown = text if len(text) <= 200 else f"{text[:200]}... ({len(text)} characters)"
        raise ServiceError(f"{what} must be JSON-encoded (e.g. '3', '\"text\"', '[1, 2]'), not {shown!r}") from None


def services(
    graph: Graph, params: ParamStore, non_finite: str = "null", interfaces: Interfaces | None = None
) -> dict[str, tuple[str, Handler]]:
    """rosapi service name -> (type, handler); parameter values' NaNs written as ``non_finite`` says; the
    details services describe the types in ``interfaces`` (others get no typedef, as rosapi answers a
    type it cannot load)."""
    known = interfaces if interfaces is not None else Interfaces()

    def encoded(value: Any) -> str:
        return json.dumps(value if non_finite == "tokens" else finite(value))

    def topics(_: dict[str, Any]) -> dict[str, Any]:
        listed = graph.topic_list()
        return {"topics": [name for name, _ in listed], "types": [kind for _, kind in listed]}

    def topics_for_type(args: dict[str, Any]) -> dict[str, Any]:
        wanted = _text(args, "type")
        return {"topics": [name for name, kind in graph.topic_list() if same_type(kind, wanted)]}

    def topic_type(args: dict[str, Any]) -> dict[str, Any]:
        name = _global(_text(args, "topic"))
        return {"type": dict(graph.topic_list()).get(name, "")}

    def service_list(_: dict[str, Any]) -> dict[str, Any]:
        return {"services": [name for name, _ in graph.service_list()]}

    def service_type(args: dict[str, Any]) -> dict[str, Any]:
        name = _global(_text(args, "service"))
        return {"type": dict(graph.service_list()).get(name, "")}

    def services_for_type(args: dict[str, Any]) -> dict[str, Any]:
        wanted = _text(args, "type")
        return {"services": [name for name, kind in graph.service_list() if same_type(kind, wanted)]}

    def nodes(_: dict[str, Any]) -> dict[str, Any]:
        return {"nodes": list(NODES)}

    def get_param(args: dict[str, Any]) -> dict[str, Any]:
        name = _global(_text(args, "name"))
        default = _text(args, "default", "") or _text(args, "default_value", "")  # ROS 1's name, ROS 2's
        if params.has(name):
            return {"value": encoded(params.get(name)), "successful": True, "reason": ""}
        if default:
            _decoded(default, "default")
            return {"value": default, "successful": True, "reason": ""}
        return {"value": "null", "successful": False, "reason": f"parameter {name!r} is not set"}

    def set_param(args: dict[str, Any]) -> dict[str, Any]:
        name = _global(_text(args, "name"))
        try:
            params.set(name, _decoded(_text(args, "value"), "value"))
        except ValueError as error:
            raise ServiceError(str(error)) from None
        return {}

    def delete_param(args: dict[str, Any]) -> dict[str, Any]:
        params.delete(_global(_text(args, "name")))  # deleting what is not set is not an error (ROS 1)
        return {}

    def has_param(args: dict[str, Any]) -> dict[str, Any]:
        return {"exists": params.has(_global(_text(args, "name")))}

    def get_param_names(_: dict[str, Any]) -> dict[str, Any]:
        return {"names": params.names()}

    def search_param(args: dict[str, Any]) -> dict[str, Any]:
        return {"global_name": params.search(_text(args, "name")) or ""}

    def get_time(_: dict[str, Any]) -> dict[str, Any]:
        secs, nsecs = divmod(time.time_ns(), 1_000_000_000)
        # ROS 1 clients (roslibpy) read secs/nsecs, ROS 2 ones sec/nanosec
        return {"time": {"secs": secs, "nsecs": nsecs, "sec": secs, "nanosec": nsecs}}

    def get_ros_version(_: dict[str, Any]) -> dict[str, Any]:
        # ROS 2's rosapi: the ops are rosbridge_suite's ros2 branch's (actions included); no ROS
        # distribution is installed, so there is none to name
        return {"version": ROS_VERSION, "distro": ""}

    # As in ROS, where rosbridge publishes and subscribes on its clients' behalf, the bridge is the node
    # at the end of every topic a client or the server uses: clients have no node names of their own.
    def published() -> list[str]:
        with graph.lock:
            return sorted(t.name for t in graph.topics.values() if t.server or t.publishers)

    def subscribed() -> list[str]:
        with graph.lock:
            return sorted(t.name for t in graph.topics.values() if t.subscribers)

    def node_details(args: dict[str, Any]) -> dict[str, Any]:
        node = _global(_text(args, "node"))
        if node != NODES[0]:
            return {"subscribing": [], "publishing": [], "services": []}
        services = [name for name, _ in graph.service_list()]
        return {"subscribing": subscribed(), "publishing": published(), "services": services}

    def publishers(args: dict[str, Any]) -> dict[str, Any]:
        return {"publishers": [NODES[0]] if _global(_text(args, "topic")) in published() else []}

    def subscribers(args: dict[str, Any]) -> dict[str, Any]:
        return {"subscribers": [NODES[0]] if _global(_text(args, "topic")) in subscribed() else []}

    def service_node(args: dict[str, Any]) -> dict[str, Any]:
        name = _global(_text(args, "service"))
        return {"node": NODES[0] if name in dict(graph.service_list()) else ""}

    def service_providers(args: dict[str, Any]) -> dict[str, Any]:
        wanted = _text(args, "service")
        return {"providers": [NODES[0]] if any(same_type(kind, wanted) for _, kind in graph.service_list()) else []}

    def topics_and_raw_types(_: dict[str, Any]) -> dict[str, Any]:
        listed = graph.topic_list()
        return {
            "topics": [name for name, _ in listed],
            "types": [kind for _, kind in listed],
            "typedefs_full_text": [known.full_text(kind) for _, kind in listed],
        }

    def message_details(args: dict[str, Any]) -> dict[str, Any]:
        return {"typedefs": known.message(_text(args, "type"))}

    def request_details(args: dict[str, Any]) -> dict[str, Any]:
        return {"typedefs": known.request(_text(args, "type"))}

    def response_details(args: dict[str, Any]) -> dict[str, Any]:
        return {"typedefs": known.response(_text(args, "type"))}

    def action_servers(_: dict[str, Any]) -> dict[str, Any]:
        return {"action_servers": [name for name, _ in graph.action_list()]}

    return {
        "/rosapi/node_details": ("rosapi/NodeDetails", node_details),
        "/rosapi/service_node": ("rosapi/ServiceNode", service_node),
        "/rosapi/service_providers": ("rosapi/ServiceProviders", service_providers),
        "/rosapi/topics_and_raw_types": ("rosapi/TopicsAndRawTypes", topics_and_raw_types),
        "/rosapi/message_details": ("rosapi/MessageDetails", message_details),
        "/rosapi/service_request_details": ("rosapi/ServiceRequestDetails", request_details),
        "/rosapi/service_response_details": ("rosapi/ServiceResponseDetails", response_details),
        "/rosapi/action_servers": ("rosapi/GetActionServers", action_servers),
        "/rosapi/topics": ("rosapi/Topics", topics),
        "/rosapi/publishers": ("rosapi/Publishers", publishers),
        "/rosapi/subscribers": ("rosapi/Subscribers", subscribers),
        "/rosapi/topics_for_type": ("rosapi/TopicsForType", topics_for_type),
        "/rosapi/topic_type": ("rosapi/TopicType", topic_type),
        "/rosapi/services": ("rosapi/Services", service_list),
        "/rosapi/service_type": ("rosapi/ServiceType", service_type),
        "/rosapi/services_for_type": ("rosapi/ServicesForType", services_for_type),
        "/rosapi/nodes": ("rosapi/Nodes", nodes),
        "/rosapi/get_param": ("rosapi/GetParam", get_param),
        "/rosapi/set_param": ("rosapi/SetParam", set_param),
        "/rosapi/delete_param": ("rosapi/DeleteParam", delete_param),
        "/rosapi/has_param": ("rosapi/HasParam", has_param),
        "/rosapi/get_param_names": ("rosapi/GetParamNames", get_param_names),
        "/rosapi/search_param": ("rosapi/SearchParam", search_param),
        "/rosapi/get_time": ("rosapi/GetTime", get_time),
        "/rosapi/get_ros_version": ("rosapi/GetROSVersion", get_ros_version),
    }
