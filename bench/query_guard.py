"""Benchmark: how deep Oxigraph's engine goes per kind of construct, and what the query guard costs.

Run: python bench/query_guard.py [--stack BYTES] [--repeat N]

Part 1 finds, for each construct that builds a deep tree (nested brackets, operator chains, group
chains), the smallest repetition count that crashes a thread with ``--stack`` bytes of stack (1 MiB
by default, the checker's), each try in a child process; it prints the stack used per level and per
character of text. The largest stack per character bounds what a text of ``DIRECT_CHARS`` can need.
Part 2 times :meth:`QueryGuard.admit` for a short text (no check), a long text checked by a warm
checker, the same text again (remembered), and a crashing text (a checker dies and a new one starts).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable

from cbrs.kb.errors import QueryTooComplexError
from cbrs.kb.query_guard import DIRECT_CHARS, QueryGuard

CONSTRUCTS: dict[str, Callable[[int], str]] = {
    "nested brackets": lambda n: "SELECT * WHERE { FILTER(" + "(" * n + "1" + ")" * n + ") }",
    "'+' chain": lambda n: "SELECT * WHERE { FILTER(" + "1+" * n + "1) }",
    "'||' chain": lambda n: "SELECT * WHERE { FILTER(" + "1||" * n + "1) }",
    "'!' chain": lambda n: "SELECT * WHERE { FILTER(" + "!" * n + "true) }",
    "UNION chain": lambda n: "SELECT * WHERE { " + "{} UNION " * n + "{} }",
    "OPTIONAL chain": lambda n: "SELECT * WHERE { ?s ?p ?o " + "OPTIONAL { ?s ?p ?o } " * n + "}",
    "BIND chain": lambda n: "SELECT * WHERE { " + " ".join(f"BIND({i} AS ?v{i})" for i in range(n)) + " }",
    "FILTER chain": lambda n: "SELECT * WHERE { ?s ?p ?o " + "FILTER(?o) " * n + "}",
    "nested sub-selects": lambda n: "SELECT * WHERE { " + "{ SELECT * WHERE " * n + "{ ?s ?p ?o }" + " }" * n + " }",
    "'STR(' nesting": lambda n: "SELECT * WHERE { FILTER(" + "STR(" * n + "1" + ")" * n + ") }",
    "'IF(' nesting": lambda n: "SELECT * WHERE { FILTER(" + "IF(1,1," * n + "1" + ")" * n + ") }",
    "'-(' nesting": lambda n: "SELECT * WHERE { FILTER(" + "-(" * n + "1" + ")" * n + ") }",
}


def child(name: str, n: int, stack: int) -> None:
    import pyoxigraph as ox

    def run() -> None:
        list(ox.Store().query(CONSTRUCTS[name](n)))  # type: ignore[arg-type]

    threading.stack_size(stack)
    worker = threading.Thread(target=run)
    worker.start()
    worker.join()


def survives(name: str, n: int, stack: int) -> bool:
    done = subprocess.run(
        [sys.executable, __file__, "--child", name, str(n), str(stack)], capture_output=True, timeout=120
    )
    return done.returncode == 0


def crash_depth(name: str, stack: int, limit: int = 200_000) -> int | None:
    n = 32
    while n <= limit and survives(name, n, stack):
        n *= 2
    if n > limit:
        return None
    low, high = n // 2, n
    while high - low > max(2, low // 50):
        middle = (low + high) // 2
        low, high = (middle, high) if survives(name, middle, stack) else (low, middle)
    return high


def timed(call: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stack", type=int, default=1024 * 1024)
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child[0], int(args.child[1]), int(args.child[2]))
        return
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.system()} {platform.release()}")
    print(f"python {platform.python_version()}, pyoxigraph {__import__('pyoxigraph').__version__}")
    print(f"\n1. crash depth with a {args.stack // 1024} KiB thread stack")
    worst = 0.0
    for name in CONSTRUCTS:
        depth = crash_depth(name, args.stack)
        if depth is None:
            print(f"  {name:20} no crash up to 200,000 levels")
            continue
        chars = len(CONSTRUCTS[name](depth))
        per_char = args.stack / chars
        worst = max(worst, per_char)
        print(
            f"  {name:20} crashes at {depth:6} levels ({chars:7} chars): "
            f"{args.stack / depth:6.0f} B/level, {per_char:5.0f} B/char"
        )
    print(
        f"  worst: {worst:.0f} B of stack per character; a text of {DIRECT_CHARS} characters needs at most "
        f"{worst * DIRECT_CHARS / 1024:.0f} KiB"
    )

    print(f"\n2. QueryGuard.admit, median of {args.repeat}")
    guard = QueryGuard()
    try:
        short = "SELECT ?s WHERE { ?s a ?c } LIMIT 1"
        direct = timed(lambda: guard.admit("query", short), args.repeat)
        print(f"  short text ({len(short)} chars), no check:  {direct * 1e6:8.1f} us")
        guard.admit("query", "SELECT * WHERE { ?s ?p ?o " + "FILTER(?o != 0) " * 100 + "}")  # start a checker
        counter = iter(range(10**9))

        def fresh_long() -> None:
            guard.admit("query", "SELECT * WHERE { ?s ?p ?o " + f"FILTER(?o != {next(counter)}) " * 100 + "}")

        print(f"  long text (1.6k chars), checked:  {timed(fresh_long, args.repeat) * 1e3:8.2f} ms")
        same = "SELECT * WHERE { ?s ?p ?o " + "FILTER(?o != -1) " * 100 + "}"
        guard.admit("query", same)
        remembered = timed(lambda: guard.admit("query", same), args.repeat)
        print(f"  the same long text, remembered:   {remembered * 1e6:8.1f} us")
        deep = CONSTRUCTS["OPTIONAL chain"](5000)

        def refused() -> None:
            try:
                guard.admit("query", deep)
            except QueryTooComplexError:
                return
            raise AssertionError("the deep text was admitted")

        print(f"  crashing text, refused (checker replaced): {timed(refused, max(3, args.repeat // 4)) * 1e3:8.1f} ms")
    finally:
        guard.close()


if __name__ == "__main__":
    main()
