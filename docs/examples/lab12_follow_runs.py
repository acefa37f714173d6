"""A lab's run log: another process that follows cbrs serve's task runs and publishes a line per event.

Written with the ``websockets`` package alone, from docs/serving.md, "The knowledge base on the bridge":
it subscribes to ``/cbrs/task_progress``, ``/cbrs/task`` and ``/cbrs/events``, advertises
``/lab12/run_log`` (``std_msgs/String``) and publishes one line there for every event, for the lab's
dashboard to show. With ``--start TASK`` it also sends the update token (``auth``) and starts the run
itself with ``/cbrs/run_task`` (``wait: false``), then ends when that run's ``/cbrs/task`` verdict comes
(exit 0 if it succeeded, 1 if not). ``--spoof`` first tries to publish a verdict on ``/cbrs/task``, which
the server's topics refuse to clients, and prints what the bridge said. With cbrs serve and the desk fan's
program running (docs/serving.md, "Tried by a lab's integrators"):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab12_follow_runs.py --start SwitchOnTheDeskFan
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import sys
from typing import Any

import websockets

TOPICS = ("/cbrs/task_progress", "/cbrs/task", "/cbrs/events")


def line(topic: str, msg: dict[str, Any]) -> str:
    """One line of the run log for an event."""
    if topic == "/cbrs/task_progress":
        what = msg.get("step") or msg.get("plan") or ""
        return f"{msg.get('run')} {msg.get('event')} {what} {msg.get('component') or ''}".rstrip()
    if topic == "/cbrs/task":
        return f"{msg.get('run')} {msg.get('task')} {msg.get('status')}: {msg.get('reason') or ''}".rstrip()
    return f"{msg.get('run') or '-'} {msg.get('event')} {msg.get('task') or ''} {msg.get('status') or ''}".rstrip()


async def follow(bridge: str, start: str | None, spoof: bool, limit: float) -> int:
    async with websockets.connect(bridge) as ws:
        await ws.send(json.dumps({"op": "set_level", "level": "warning"}))
        for topic in TOPICS:
            await ws.send(json.dumps({"op": "subscribe", "topic": topic}))
        await ws.send(json.dumps({"op": "advertise", "topic": "/lab12/run_log", "type": "std_msgs/String"}))
        if spoof:
            await ws.send(
                json.dumps({"op": "publish", "topic": "/cbrs/task", "msg": {"task": "X", "status": "succeeded"}})
            )
        run = None
        if start:
            await ws.send(json.dumps({"op": "auth", "mac": os.environ.get("CBRS_UPDATE_TOKEN", "")}))
            call = {"task": start, "wait": False}
            await ws.send(json.dumps({"op": "call_service", "service": "/cbrs/run_task", "args": call, "id": "start"}))
        async with asyncio.timeout(limit):
            async for text in ws:
                frame = json.loads(text)
                if frame.get("op") == "status":
                    print(f"bridge {frame.get('level')}: {frame.get('msg')}", flush=True)
                elif frame.get("op") == "service_response" and frame.get("id") == "start":
                    if not frame.get("result"):
                        print(f"the run was refused: {frame.get('values')}", flush=True)
                        return 2
                    run = frame["values"]["id"]
                    print(f"started {run}", flush=True)
                elif frame.get("op") == "publish" and frame.get("topic") in TOPICS:
                    text = line(frame["topic"], frame["msg"])
                    print(text, flush=True)
                    await ws.send(json.dumps({"op": "publish", "topic": "/lab12/run_log", "msg": {"data": text}}))
                    if start and frame["topic"] == "/cbrs/task" and frame["msg"].get("run") == run:
                        return 0 if frame["msg"].get("status") == "succeeded" else 1
    return 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090")
    parser.add_argument("--start", metavar="TASK", help="start this task and end with its verdict")
    parser.add_argument("--spoof", action="store_true", help="first try to publish on /cbrs/task")
    parser.add_argument("--seconds", type=float, default=120.0, help="give up after this long")
    options = parser.parse_args()
    try:
        sys.exit(asyncio.run(follow(options.bridge, options.start, options.spoof, options.seconds)))
    except TimeoutError:
        print(f"no verdict within {options.seconds} s", file=sys.stderr)
        sys.exit(3)
