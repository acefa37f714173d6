"""How much each part of cbrs installs: the core, then what the [sim] and [eval] extras add.

    python bench/install_sizes.py

Sizes are the files of each distribution in this environment (what pip installed for it), over the
dependency closure of cbrs alone, then of each extra beyond the core. The machine and Python are printed.
"""

from __future__ import annotations

import importlib.metadata as md
import os
import platform
import re

from packaging.requirements import Requirement


def _size(name: str) -> int:
    dist = md.distribution(name)
    return sum(p.locate().stat().st_size for p in dist.files or [] if p.locate().is_file())


def closure(requirements: list[str], extras: set[str] = frozenset()) -> set[str]:
    """The distributions ``requirements`` pull in (their markers evaluated with ``extras``)."""
    found: set[str] = set()
    pending = list(requirements)
    while pending:
        req = Requirement(pending.pop())
        name = re.sub(r"[-_.]+", "-", req.name).lower()
        if req.marker is not None and not any(req.marker.evaluate({"extra": e}) for e in (extras or {""})):
            continue
        if name in found:
            continue
        try:
            dist = md.distribution(name)
        except md.PackageNotFoundError:
            continue
        found.add(name)
        for sub in dist.requires or []:
            sub_req = Requirement(sub)
            if sub_req.marker is None or sub_req.marker.evaluate({"extra": ""}):
                pending.append(sub)
        for extra in req.extras:
            pending += [r.split(";")[0] for r in dist.requires or [] if f'extra == "{extra}"' in r]
    return found


def main() -> None:
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    own = [r for r in md.distribution("cbrs").requires or []]
    core_reqs = [r for r in own if ";" not in r]
    core = closure(core_reqs) | {"cbrs"}
    print(f"{'part':<8} {'distributions':>13} {'MiB':>8}")
    print(f"{'core':<8} {len(core):>13} {sum(_size(d) for d in core) / 2**20:>8.1f}")
    for extra in ("sim", "eval"):
        reqs = [r.split(";")[0] for r in own if f'extra == "{extra}"' in r]
        added = closure(reqs) - core
        mib = sum(_size(d) for d in added) / 2**20
        print(f"{'+' + extra:<8} {len(added):>13} {mib:>8.1f}   ({', '.join(sorted(added))})")


if __name__ == "__main__":
    main()
