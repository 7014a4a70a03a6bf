"""Hypothesis settings profiles for the machines, the run's seed and
example database: the database keeps failing examples
so that the next run, or another bench, tries them first."""

from __future__ import annotations

import os
import re
import secrets
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from hypothesis import HealthCheck, Phase, settings
from hypothesis.configuration import set_hypothesis_home_dir
from hypothesis.database import DirectoryBasedExampleDatabase, ExampleDatabase

# every field pinned: Hypothesis loads its own profile when CI is set in the environment
# (derandomized, among others), and an unpinned field would be inherited from it
_COMMON = {"suppress_health_check": list(HealthCheck), "deadline": None,
           "database": None, "print_blob": False, "report_multiple_bugs": True}

PROFILES = {
    "ci": settings(max_examples=8, stateful_step_count=12, derandomize=True, **_COMMON),
    "dev": settings(max_examples=40, stateful_step_count=25, derandomize=False, **_COMMON),
    "thorough": settings(max_examples=300, stateful_step_count=50, derandomize=False,
                         **_COMMON),
    # real time is dear: no shrinking (a failing example is reported as it ran); the
    # examples other benches found failing are tried first
    "hardware": settings(max_examples=3, stateful_step_count=10, derandomize=True,
                         phases=[Phase.explicit, Phase.reuse, Phase.generate], **_COMMON),
    # the mutation score: ci's examples, a failure counts as it is found (no shrinking)
    "mutation": settings(max_examples=8, stateful_step_count=12, derandomize=True,
                         phases=[Phase.explicit, Phase.generate], **_COMMON),
}


#: the seed of the derandomized profiles' machines: Hypothesis refuses an example
#: database with derandomize, and a fixed seed draws the same examples every run as well
EXACT_SEED = 0

#: the default example database: this folder under the report folder (the command line)
#: or pytest's rootdir (the plugin)
DEFAULT_DATABASE = ".gve-hypothesis"

REDIS_SCHEMES = ("redis://", "rediss://", "unix://")

_database: str | None = None    # where this run keeps failing examples; None: nowhere
_opened: dict[tuple[str, str], ExampleDatabase] = {}


def get(name: str) -> settings:
    try:
        return PROFILES[name]
    except KeyError:
        raise ValueError(f"unknown settings profile {name!r}: {', '.join(PROFILES)}") from None


def run_seed(names: list[str], seed: int | None = None) -> int | None:
    """The seed a run records and gives the machines: ``seed`` when given (it overrides
    derandomization), else None when every settings profile ``names`` is derandomized
    (every run draws the same examples), else a fresh random one, so that any run can be
    replayed."""
    if seed is not None:
        return seed
    if all(get(name).derandomize for name in names):
        return None
    return fresh_seed()


def fresh_seed() -> int:
    """A seed of its own for a run given none, printed and recorded so it can be
    replayed."""
    return secrets.randbits(32)


def machine_run(base: settings, profile: str, seed: int | None) -> tuple[settings, int | None]:
    """The settings and the seed a machine runs with against ``profile``: the run's
    example database applied, and a derandomized profile's examples drawn from
    :data:`EXACT_SEED` unless the run has a seed of its own."""
    db = database_for(profile)
    if base.derandomize:
        return settings(base, derandomize=False, database=db), (
            EXACT_SEED if seed is None else seed)
    return settings(base, database=db), seed


@contextmanager
def example_database(where: str | None) -> Iterator[None]:
    """Keep the failing examples of the machines run inside at ``where``: a directory,
    ``redis://HOST:PORT/N`` (shared by benches) or ``none``. Raises ValueError, before
    anything runs, when it cannot be used."""
    global _database
    where = None if where is None or where.lower() == "none" else where
    if where is not None:
        _check(where)
    before, _database = _database, where
    try:
        with _hypothesis_home():
            yield
    finally:
        _database = before


@contextmanager
def _hypothesis_home() -> Iterator[None]:
    """Hypothesis keeps more than examples under its home folder (a cache of the constants
    it found in the code, `.hypothesis/` in the working directory by default): a run keeps
    that in a temporary folder, removed at its end, so that only the example database
    stays, where the run chose."""
    with tempfile.TemporaryDirectory(prefix="gve-hypothesis-", ignore_cleanup_errors=True) as home:
        set_hypothesis_home_dir(home)
        try:
            yield
        finally:
            set_hypothesis_home_dir(None)


def database_for(profile: str) -> ExampleDatabase | None:
    """The run's example database as one profile sees it: each profile has its own keys,
    so that a run that passes on one profile never deletes what failed on another."""
    if _database is None:
        return None
    key = (_database, profile)
    if key not in _opened:
        _opened[key] = (_redis(_database, profile) if _database.startswith(REDIS_SCHEMES)
                        else DirectoryBasedExampleDatabase(Path(_database) / profile))
    return _opened[key]


def _check(where: str) -> None:
    if where.startswith(REDIS_SCHEMES):
        _redis_client(where)
        return
    if not where.strip():
        raise ValueError("an empty name: give a directory, redis://HOST:PORT/N or none")
    if re.match(r"[A-Za-z][A-Za-z0-9+.-]*://", where):
        raise ValueError(f"{where}: unknown scheme (a directory, "
                         f"{', '.join(s + '...' for s in REDIS_SCHEMES)} or none)")
    # created when the first failing example is saved: a run that fails nothing leaves
    # no folder behind
    path = Path(where).absolute()
    if path.exists() and not path.is_dir():
        raise ValueError(f"example database {where}: not a directory")
    parent = next(p for p in (path, *path.parents) if p.exists())
    if not (parent.is_dir() and os.access(parent, os.W_OK | os.X_OK)):
        raise ValueError(f"example database {where}: {parent} is not a writable directory")


def _redis(url: str, profile: str) -> ExampleDatabase:
    from hypothesis.extra.redis import RedisExampleDatabase
    return RedisExampleDatabase(_redis_client(url),
                                key_prefix=f"gve-example:{profile}:".encode())


def _redis_client(url: str):  # -> redis.Redis, an optional dependency
    try:
        from redis import Redis, RedisError
    except ImportError:
        raise ValueError(f"example database {url}: needs the redis package (install the "
                         "suite with its [redis] extra, e.g. pip install "
                         "'./gve-conformance[redis]')") from None
    try:
        client = Redis.from_url(url, socket_connect_timeout=5, socket_timeout=30)
        client.ping()
    except (RedisError, ValueError) as err:
        raise ValueError(f"example database {url}: {err}") from None
    return client
