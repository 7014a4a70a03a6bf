"""Jobs side by side in worker processes, or in this process when there is one job."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import AbstractContextManager
from typing import Any


class _Serial:
    """One job: no worker processes."""

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any]) -> Iterator[Any]:
        return map(fn, items)


def workers(jobs: int) -> AbstractContextManager:
    """A pool whose ``map`` runs ``jobs`` at a time (in order of the items)."""
    return ProcessPoolExecutor(jobs) if jobs > 1 else _Serial()
