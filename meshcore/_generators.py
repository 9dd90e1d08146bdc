"""Draining the progress generators (:func:`meshcore.iterate`, :func:`meshcore.run_block`, ...)."""

from __future__ import annotations

from collections.abc import Callable, Generator
from typing import Any

__all__ = ["drain"]


def drain(gen: Generator[Any, Any, Any], callback: Callable[[Any], Any] | None = None) -> Any:
    """Run ``gen`` to its end and return its value; ``callback(item)`` sees every item.

    A callback that returns ``"stop"`` (or ``False``) sends ``"stop"`` to the generator.
    """
    try:
        item = next(gen)
        while True:
            cmd = callback(item) if callback is not None else None
            item = gen.send("stop" if cmd in ("stop", False) else None)
    except StopIteration as fin:
        return fin.value
