"""The desk fan's smart plug as two cbrs components, written with the ``websockets`` package alone.

An integrator's program from docs/components.md, "The protocol", step by step, with no cbrs import:
open the bridge, send the update token (the ``auth`` op), register lab12_fan_switch.ttl (both
components in one ``/cbrs/register`` call), advertise the two services its ``cbrs:topic``s name, beat
``/cbrs/heartbeat`` once a second on a schedule of its own, and answer the ``call_service`` frames with
the fan's new status. A real plug switches its relay in ``switch``. ``--delay S`` answers each call S
seconds late (to kill the program mid-call); the program exits 1 when the bridge closes or the
heartbeat says the component was deregistered, for a supervisor to restart it. With cbrs serve's
bridge and lab12_desk_fan.ttl loaded (docs/serving.md, "Tried by a lab's integrators"):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab12_fan_switch.py --bridge ws://127.0.0.1:9090
"""

from __future__ import annotations

import argparse
import asyncio
import itertools
import json
import os
import sys
from pathlib import Path
from typing import Any

import websockets

HERE = Path(__file__).resolve().parent
SERVICES = {
    "/lab12_fan_plug_01/switch_on": "home:SwitchedOn",
    "/lab12_fan_plug_01/switch_off": "home:SwitchedOff",
}
ids = itertools.count(1)


def log(text: str) -> None:
    print(f"fan plug: {text}", file=sys.stderr, flush=True)


def switch(status: str) -> None:
    """Switch the relay; a real plug does it here."""
    log(f"the fan is now {status}")


async def call(ws: Any, pending: dict[str, asyncio.Future[Any]], service: str, args: dict[str, Any]) -> Any:
    """Call a bridge service and wait for its response frame (read by ``receive``)."""
    call_id = f"fan-{next(ids)}"
    answer: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
    pending[call_id] = answer
    await ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": call_id}))
    return await asyncio.wait_for(answer, 30)


async def answer_call(ws: Any, frame: dict[str, Any], delay: float) -> None:
    status = SERVICES[frame["service"]]
    log(f"{frame['service']} called for {frame.get('args', {}).get('fan')}")
    if delay:
        await asyncio.sleep(delay)
    switch(status)
    reply = {"fanStatus": {"@type": status}}
    await ws.send(
        json.dumps(
            {
                "op": "service_response",
                "service": frame["service"],
                "id": frame.get("id"),
                "result": True,
                "values": reply,
            }
        )
    )


async def receive(ws: Any, pending: dict[str, asyncio.Future[Any]], delay: float) -> None:
    answering: set[asyncio.Task[None]] = set()  # each call answered on its own, so a slow one holds no other
    async for text in ws:
        frame = json.loads(text)
        if frame.get("op") == "service_response" and frame.get("id") in pending:
            pending.pop(frame["id"]).set_result(frame)
        elif frame.get("op") == "call_service" and frame.get("service") in SERVICES:
            task = asyncio.create_task(answer_call(ws, frame, delay))
            answering.add(task)
            task.add_done_callback(answering.discard)
        elif frame.get("op") == "status":
            log(f"bridge status {frame.get('level')}: {frame.get('msg')}")


async def heartbeat(ws: Any, pending: dict[str, asyncio.Future[Any]]) -> str:
    """Beat once a second; return why it stopped."""
    loop = asyncio.get_running_loop()
    next_beat = loop.time()
    while True:
        next_beat += 1.0
        await asyncio.sleep(max(0.0, next_beat - loop.time()))
        beat = await call(ws, pending, "/cbrs/heartbeat", {})
        if not beat.get("result"):
            return str(beat.get("values"))


async def main(bridge: str, token: str, delay: float) -> int:
    description = (HERE / "lab12_fan_switch.ttl").read_text()
    pending: dict[str, asyncio.Future[Any]] = {}
    async with websockets.connect(bridge) as ws:
        reader = asyncio.create_task(receive(ws, pending, delay))
        await ws.send(json.dumps({"op": "auth", "mac": token}))
        reg = await call(ws, pending, "/cbrs/register", {"description": description, "format": "turtle", "ttl": 3.0})
        if not reg.get("result"):
            log(f"registration refused: {reg.get('values')}")
            return 2
        log(f"registered {reg['values']}")
        for service in SERVICES:
            await ws.send(json.dumps({"op": "advertise_service", "service": service, "type": "lab12_msgs/Switch"}))
        beats = asyncio.create_task(heartbeat(ws, pending))
        done, _ = await asyncio.wait({reader, beats}, return_when=asyncio.FIRST_COMPLETED)
        if beats in done and not beats.exception():
            log(f"heartbeat refused: {beats.result()}")
        else:
            log("the bridge closed the connection")
        for task in (reader, beats):
            task.cancel()
    return 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090")
    parser.add_argument("--delay", type=float, default=0.0, help="answer each call this many seconds late")
    options = parser.parse_args()
    token = os.environ.get("CBRS_UPDATE_TOKEN", "")
    try:
        sys.exit(asyncio.run(main(options.bridge, token, options.delay)))
    except (OSError, websockets.exceptions.WebSocketException) as error:
        log(f"no bridge at {options.bridge}: {error}")
        sys.exit(1)
