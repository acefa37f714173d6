"""The lab's bedroom hygrometer as a cbrs component written with plain websockets and JSON, following
docs/components.md, "The protocol": open the bridge's websocket, send the update token with the auth op,
call /cbrs/register with the description (lab8_bedroom_hygrometer.ttl), advertise its service, beat
/cbrs/heartbeat about once a second and answer the server's calls with the bedroom's relative humidity.

With cbrs serve started with CBRS_UPDATE_TOKEN and lab8_bedroom_humidity.ttl in the requirements:

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab8_bedroom_hygrometer.py [--bridge ws://127.0.0.1:9090]
    CBRS_UPDATE_TOKEN=secret cbrs --store http://127.0.0.1:8080 run BedroomHumidity --bridge ws://127.0.0.1:9090

It prints "hygrometer: registered ..." once registered and "hygrometer: read ..." at each call. On purpose,
``--misbehave die`` exits (status 3) when it is called, before answering (a program that crashes
mid-task); ``--misbehave slow`` answers after 15 s; ``--misbehave unit`` answers the humidity as a text
with its unit, "47.5 %", where a number is meant.
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
SERVICE, TYPE, LEASE = "/lab8_hygrometer_01/read", "lab8_msgs/Humidity", 3.0


def reading(misbehave: str) -> dict[str, Any]:
    """The answer's one field, named by the description's output (cbrs:parameterName "humidity")."""
    percent: Any = "47.5 %" if misbehave == "unit" else 47.5
    return {"humidity": {"@type": "home:Humidity", "percent": percent}}


async def serve(bridge: str, token: str, misbehave: str) -> str:
    """Serve until the server ends it; the reason."""
    ids = (f"hygrometer-{n}" for n in itertools.count(1))
    async with websockets.connect(bridge) as ws:
        await ws.send(json.dumps({"op": "auth", "mac": token}))
        register = next(ids)
        description = (HERE / "lab8_bedroom_hygrometer.ttl").read_text(encoding="utf-8")
        args = {"description": description, "format": "turtle", "ttl": LEASE}
        await ws.send(json.dumps({"op": "call_service", "service": "/cbrs/register", "id": register, "args": args}))
        while True:
            message = json.loads(await ws.recv())
            if message.get("op") == "service_response" and message.get("id") == register:
                break
        if not message.get("result"):
            return f"registration refused: {message.get('values')}"
        print(f"hygrometer: registered {message.get('values')}", flush=True)
        await ws.send(json.dumps({"op": "advertise_service", "service": SERVICE, "type": TYPE}))
        beats: set[str] = set()

        async def beat() -> None:
            while True:
                beats.add(beat_id := next(ids))
                await ws.send(json.dumps({"op": "call_service", "service": "/cbrs/heartbeat", "id": beat_id}))
                await asyncio.sleep(LEASE / 3)

        beating = asyncio.create_task(beat())
        try:
            async for text in ws:
                message = json.loads(text)
                if message.get("op") == "call_service" and message.get("service") == SERVICE:
                    if misbehave == "die":
                        print("hygrometer: called, and dying before it answers", flush=True)
                        os._exit(3)
                    if misbehave == "slow":
                        await asyncio.sleep(15.0)
                    values = reading(misbehave)
                    print(f"hygrometer: read {values['humidity']['percent']}", flush=True)
                    reply = {"op": "service_response", "service": SERVICE, "id": message.get("id"), "result": True}
                    await ws.send(json.dumps({**reply, "values": values}))
                elif message.get("op") == "service_response" and message.get("id") in beats:
                    beats.discard(message["id"])
                    if not message.get("result"):
                        return str(message.get("values"))
            return "the server closed the connection"
        finally:
            beating.cancel()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    parser.add_argument("--misbehave", choices=("no", "die", "slow", "unit"), default="no")
    args = parser.parse_args()
    try:
        reason = asyncio.run(serve(args.bridge, os.environ.get("CBRS_UPDATE_TOKEN", ""), args.misbehave))
    except (OSError, websockets.ConnectionClosed) as error:
        reason = f"the connection failed: {error}"
    except KeyboardInterrupt:
        return 0
    print(f"hygrometer: stopped serving: {reason}", file=sys.stderr, flush=True)
    return 1


if __name__ == "__main__":
    sys.exit(main())
