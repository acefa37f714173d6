"""Benchmark: how long a store takes to open after its process was killed with a large write-ahead log.

Run: python bench/wal_recovery.py [--wal-mb M] [--batch N]

A child process opens a fresh on-disk store and adds quads in transactions of N until RocksDB's
write-ahead log files (``*.log``) hold M MiB, then is killed with SIGKILL: no flush, no close, as a
crash or an OOM kill leaves it. A second child then opens the store and counts its quads (the recovery:
RocksDB replays the log into memtables). The anchor is the same store opened again after that child
closed it cleanly. Prints the machine, the inputs, the log size, both opening times and their ratio.
"""

from __future__ import annotations

import argparse
import os
import platform
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

WRITER = """
import sys, pathlib, pyoxigraph as ox
path, target, batch = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
store = ox.Store(path)
graph = ox.NamedNode("urn:bench:graph")
number = 0
while True:
    store.extend(
        ox.Quad(ox.NamedNode(f"urn:bench:s{number + i}"), ox.NamedNode("urn:bench:p"),
                ox.Literal("x" * 200 + str(number + i)), graph)
        for i in range(batch)
    )
    number += batch
    wal = sum(p.stat().st_size for p in pathlib.Path(path).glob("*.log"))
    if wal >= target:
        print(number, wal, flush=True)
        sys.stdin.readline()  # wait to be killed
"""

OPENER = """
import sys, time, pyoxigraph as ox
started = time.perf_counter()
store = ox.Store(sys.argv[1])
opened = time.perf_counter() - started
count = sum(1 for _ in store.quads_for_pattern(None, None, None, None))
print(opened, time.perf_counter() - started, count, flush=True)
store.flush()
"""


def open_store(path: Path) -> tuple[float, float, int]:
    done = subprocess.run([sys.executable, "-c", OPENER, str(path)], capture_output=True, text=True, timeout=3600)
    opened, counted, count = done.stdout.split()
    return float(opened), float(counted), int(count)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wal-mb", type=int, default=256)
    parser.add_argument("--batch", type=int, default=1000)
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(
        f"inputs: quads of a ~210-character literal, {args.batch} per transaction, "
        f"until the WAL holds {args.wal_mb} MiB"
    )
    with tempfile.TemporaryDirectory(prefix="cbrs-wal-") as folder:
        path = Path(folder) / "store"
        writer = subprocess.Popen(
            [sys.executable, "-c", WRITER, str(path), str(args.wal_mb << 20), str(args.batch)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert writer.stdout is not None
        written, wal = writer.stdout.readline().split()
        writer.send_signal(signal.SIGKILL)
        writer.wait(60)
        size = sum(p.stat().st_size for p in path.iterdir() if p.is_file())
        print(
            f"killed after {int(written)} quads: WAL {int(wal) / 2**20:.0f} MiB, store directory {size / 2**20:.0f} MiB"
        )
        recovered = open_store(path)  # replays the log
        clean = open_store(path)  # the anchor: the same data, closed cleanly by the previous opener
    print(f"\n{'open':28} {'open s':>8} {'open+count s':>13} {'quads':>9}")
    print(f"{'after SIGKILL (recovery)':28} {recovered[0]:8.2f} {recovered[1]:13.2f} {recovered[2]:9d}")
    print(f"{'after a clean close':28} {clean[0]:8.2f} {clean[1]:13.2f} {clean[2]:9d}")
    print(f"recovery open / clean open: {recovered[0] / clean[0]:.1f}x; quads lost: {int(written) - recovered[2]}")
    print(f"recovery rate: {int(wal) / 2**20 / recovered[0]:.0f} MiB of WAL per second")


if __name__ == "__main__":
    main()
