import pytest

from conformance.reports import plots


@pytest.fixture
def no_plots(monkeypatch):
    """Pages without pictures, for tests about something else (drawing takes time)."""
    monkeypatch.setattr(plots, "available", lambda: False)
