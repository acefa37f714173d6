"""A rosbridge v2 server without ROS: topics, services, actions and parameters for non-ROS nodes and web pages.

ROS clients (roslibpy, roslibjs) and plain websocket clients (a sensor board, a web page) talk to cbrs
with the rosbridge v2 protocol: JSON text frames over a websocket. See docs/rosbridge.md.

The Python API the rest of cbrs uses::

    from cbrs.rosbridge import Bridge, GoalHandle, GoalResult, GoalStatus, ServiceError

    bridge = Bridge(max_message_bytes=1 << 20, call_timeout=30.0, params={"/robot/speed": 0.5})

    def locate(args: dict) -> dict:         # runs on a worker thread; may block for seconds
        if "robot" not in args:
            raise ServiceError("missing field 'robot'")   # -> result false, values "missing field 'robot'"
        return {"x": 1.0, "y": 2.0}          # -> result true, values {"x": 1.0, "y": 2.0}

    bridge.add_service("/cbrs/locate", "cbrs/Locate", locate)

    def count(goal: GoalHandle) -> dict:     # an action: runs on a worker thread until its goal ends
        for n in range(goal.args.get("to", 3)):
            if goal.cancel_requested:
                return GoalResult(GoalStatus.CANCELED, {"reached": n})
            goal.publish_feedback({"n": n})  # -> action_feedback, if the client asked for feedback
        return {"reached": goal.args.get("to", 3)}   # -> action_result, status SUCCEEDED

    bridge.add_action("/cbrs/count", "cbrs/Count", count)
    bridge.add_topic("/cbrs/events", "cbrs/Event")   # listed by rosapi; latch=True keeps the last message
    running = bridge.start(host="127.0.0.1", port=9090)  # a background thread with its own event loop
    bridge.publish("/cbrs/events", {"event": "ready"})  # from any thread
    print(running.port, running.url)          # port=0 picks a free port
    running.stop(timeout=5.0)                 # closes the connections, joins the threads

Any other exception in a handler fails the call with ``internal error: <type>: <message>`` and is
logged. ``await bridge.serve(host, port)`` serves in the running event loop instead, until cancelled.
``bridge.params`` is the thread-safe parameter store rosapi's ``get_param``/``set_param`` use;
``bridge.interfaces.load(directory, package)`` reads ``.msg``/``.srv`` files for rosapi's typedefs.
``remove_service``, ``remove_action``, ``topics()``, ``services()`` and ``actions()`` complete the server
side. Logging goes to the ``cbrs.rosbridge`` logger.
"""

from cbrs.rosbridge.bridge import Bridge
from cbrs.rosbridge.errors import ProtocolError, RosbridgeError, ServiceError, UnknownTopicError
from cbrs.rosbridge.goals import GoalHandle, GoalResult, GoalStatus
from cbrs.rosbridge.interfaces import InterfaceError, Interfaces
from cbrs.rosbridge.params import ParamStore
from cbrs.rosbridge.server import RunningBridge, serve, start
from cbrs.rosbridge.session import Caller, current_caller

__all__ = [
    "Bridge",
    "Caller",
    "GoalHandle",
    "GoalResult",
    "GoalStatus",
    "InterfaceError",
    "Interfaces",
    "ParamStore",
    "ProtocolError",
    "RosbridgeError",
    "RunningBridge",
    "ServiceError",
    "UnknownTopicError",
    "current_caller",
    "serve",
    "start",
]
