"""Query results let go of on the thread that read them, even when reading them fails.

pyoxigraph's SELECT and CONSTRUCT results (``QuerySolutions``, ``QueryTriples``) and its pattern
iterator (``QuadIter``) may only be dropped on the thread that made them; dropped on another, pyoxigraph
reports "is unsendable, but is being dropped on another thread" and leaks them. A function that holds
one in a local and raises leaves it in its frame, which the error's traceback keeps alive: wherever
the error ends (a request thread that a worker handed it to, an event loop), or wherever a garbage
collection breaks a reference cycle the error is in, the result goes with it. :func:`releases_results`
clears the frames of such a function before its error leaves, so results go where they were made.
"""

from __future__ import annotations

import functools
import traceback
from collections.abc import Callable
from typing import ParamSpec, TypeVar

__all__ = ["releases_results"]

_P = ParamSpec("_P")
_R = TypeVar("_R")


def releases_results(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """``function``, whose errors leave with its frame and those below cleared of their locals (their
    lines stay in the traceback): what it read is dropped here, on its own thread."""

    @functools.wraps(function)
    def run(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        try:
            return function(*args, **kwargs)
        except BaseException as error:
            del args, kwargs  # a result passed in is let go of too
            if error.__traceback__ is not None:
                traceback.clear_frames(error.__traceback__.tb_next)  # not this running frame: it cannot be
            raise

    return run
