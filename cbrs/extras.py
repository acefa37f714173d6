"""The optional parts of cbrs, and the clear error a command gets when the part it needs is not installed.

The knowledge base, the endpoint, the bridge and matchmaking install with ``pip install cbrs``. The
simulated home (pybullet, Pillow) is the ``sim`` extra; the text-aware matching method and every
drawing and plot (scikit-learn, matplotlib) are the ``eval`` extra: ``pip install 'cbrs[sim,eval]'``.
"""

from __future__ import annotations

import importlib.util

from cbrs.kb.errors import KnowledgeBaseError

__all__ = ["EXTRAS", "MissingExtraError", "installed", "require"]

EXTRAS: dict[str, tuple[str, ...]] = {
    "sim": ("pybullet", "PIL"),
    "eval": ("sklearn", "matplotlib"),
}
"""Each extra and the modules it brings."""


class MissingExtraError(KnowledgeBaseError):
    """What was asked for needs an optional part of cbrs that is not installed."""

    http_status = 501

    def __init__(self, extra: str, what: str, missing: str) -> None:
        self.extra = extra
        self.what = what
        super().__init__(
            f"{what} needs the optional part [{extra}] of cbrs ({missing} is not installed): "
            f"pip install 'cbrs[{extra}]'"
        )


def installed(extra: str) -> bool:
    """Whether every module of ``extra`` can be imported."""
    return all(importlib.util.find_spec(module) is not None for module in EXTRAS[extra])


def require(extra: str, what: str) -> None:
    """Raise :class:`MissingExtraError` naming ``what`` unless ``extra`` is installed."""
    for module in EXTRAS[extra]:
        if importlib.util.find_spec(module) is None:
            raise MissingExtraError(extra, what, module)
