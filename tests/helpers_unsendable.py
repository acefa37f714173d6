"""Which pyoxigraph results an error still holds: those may only be dropped on the thread that made them."""

from __future__ import annotations

import pyoxigraph as ox

UNSENDABLE = (ox.QuerySolutions, ox.QueryTriples, type(ox.Store().quads_for_pattern(None, None, None)))


def unsendable_kept_by(error: BaseException) -> list[str]:
    """``function: local`` for every pyoxigraph result a frame of ``error``'s tracebacks (its causes and
    contexts too) still holds."""
    kept: list[str] = []
    seen: set[int] = set()
    pending: list[BaseException | None] = [error]
    while pending:
        current = pending.pop()
        if current is None or id(current) in seen:
            continue
        seen.add(id(current))
        pending += [current.__cause__, current.__context__]
        trace = current.__traceback__
        while trace is not None:
            frame = trace.tb_frame
            kept += [
                f"{frame.f_code.co_name}: {name}"
                for name, value in frame.f_locals.items()
                if isinstance(value, UNSENDABLE)
            ]
            trace = trace.tb_next
    return kept
