"""Fixtures of the fleet tests: a Redis server and emulated units on TCP ports."""

from __future__ import annotations

import pytest

from tests.conformance.fleet.services import redis_server, tcp_unit


@pytest.fixture
def redis_url(tmp_path):
    """A Redis server of the test's own; the test is skipped, saying why, without one."""
    try:
        server, url = redis_server(tmp_path)
    except LookupError as why:
        pytest.skip(f"no Redis server for the shared example database: {why}")
    yield url
    server.stop()


@pytest.fixture
def tcp_units():
    """Start emulated units on TCP ports: ``tcp_units(*emulator_args) -> 'HOST:PORT'``;
    all stopped after the test."""
    started = []

    def start(*args: str) -> str:
        unit, where = tcp_unit(*args)
        started.append(unit)
        return where

    yield start
    for unit in started:
        unit.stop()
