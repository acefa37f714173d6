"""The lab's kettle switch as a cbrs component written with plain websockets, following
docs/components.md, "The protocol", step by step: open the bridge's websocket, send the update token
with the auth op, call /cbrs/register with the description (lab6_kettle_switch_on.ttl), then advertise
its service, then call /cbrs/heartbeat about once a second on a schedule and answer the server's calls.

With the server of docs/tasks.md, "A sixth round" (lab6_kettle.ttl in the ontology and the map,
lab6_switch_on_the_kettle.ttl in the requirements, cbrs serve started with CBRS_UPDATE_TOKEN):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab6_kettle.py [--bridge ws://127.0.0.1:9090]
    CBRS_UPDATE_TOKEN=secret cbrs --store http://127.0.0.1:8080 run SwitchOnTheKettle --bridge ws://127.0.0.1:9090

It prints "kettle: registered ..." once registered and "kettle: switched on" at each call, and exits with
status 1 and the reason when the server closes the connection, refuses it or deregisters it.
``--answer off`` answers home:SwitchedOff to "switch on" (a relay wired backwards), on purpose.
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
SERVICE, TYPE, LEASE = "/lab6_kettle_switch_01/switch_on", "lab6_msgs/SwitchOn", 3.0


async def serve(bridge: str, token: str, answer: str) -> str:
    """Serve until the server ends it; the reason."""
    ids = (f"kettle-{n}" for n in itertools.count(1))
    async with websockets.connect(bridge) as ws:
        await ws.send(json.dumps({"op": "auth", "mac": token}))  # 2. the update token
        register = next(ids)
        description = (HERE / "lab6_kettle_switch_on.ttl").read_text(encoding="utf-8")
        args = {"description": description, "format": "turtle", "ttl": LEASE}
        await ws.send(json.dumps({"op": "call_service", "service": "/cbrs/register", "id": register, "args": args}))
        while True:  # 3. register, and wait for its answer
            message = json.loads(await ws.recv())
            if message.get("op") == "service_response" and message.get("id") == register:
                break
        if not message.get("result"):
            return f"registration refused: {message.get('values')}"
        print(f"kettle: registered {message.get('values')}", flush=True)
        await ws.send(json.dumps({"op": "advertise_service", "service": SERVICE, "type": TYPE}))  # 4. then provide
        beats: set[str] = set()

        async def beat() -> None:  # 5. about once a second, on a schedule, without waiting for the answer
            while True:
                beats.add(beat_id := next(ids))
                await ws.send(json.dumps({"op": "call_service", "service": "/cbrs/heartbeat", "id": beat_id}))
                await asyncio.sleep(LEASE / 3)

        beating = asyncio.create_task(beat())
        try:
            async for text in ws:
                message = json.loads(text)
                if message.get("op") == "call_service" and message.get("service") == SERVICE:
                    print(f"kettle: switched {answer} (asked for {message.get('args', {}).get('kettle')})", flush=True)
                    status = "home:SwitchedOn" if answer == "on" else "home:SwitchedOff"
                    values: dict[str, Any] = {"kettleStatus": {"@type": status}}
                    reply = {"op": "service_response", "service": SERVICE, "id": message.get("id"), "result": True}
                    await ws.send(json.dumps({**reply, "values": values}))
                elif message.get("op") == "service_response" and message.get("id") in beats:
                    beats.discard(message["id"])
                    reason = str(message.get("values"))
                    if not message.get("result") and "this session has no live component" in reason:
                        return f"its lease lapsed ({reason}); a supervisor restarts it, and it registers afresh"
                    if not message.get("result"):
                        return reason  # deregistered, or its service not advertised
            return "the server closed the connection"
        finally:
            beating.cancel()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    parser.add_argument("--answer", choices=("on", "off"), default="on", help="the status it answers")
    args = parser.parse_args()
    try:
        reason = asyncio.run(serve(args.bridge, os.environ.get("CBRS_UPDATE_TOKEN", ""), args.answer))
    except (OSError, websockets.ConnectionClosed) as error:
        reason = f"the connection failed: {error}"
    except KeyboardInterrupt:
        return 0
    print(f"kettle: stopped serving: {reason}", file=sys.stderr, flush=True)
    return 1


if __name__ == "__main__":
    sys.exit(main())
