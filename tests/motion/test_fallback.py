"""Without the C core the emulator uses the Python twin and says so once on stderr;
GVE_STEPPER forces a core."""

from __future__ import annotations

import pytest

import emulator.motion.factory as motion
from emulator.motion.python_twin import PythonMotion


def _missing():
    raise ImportError("No module named 'emulator.motion._stepper_c'")


def test_falls_back_once_with_a_message(monkeypatch, capsys):
    monkeypatch.setattr(motion, "_c_class", _missing)
    monkeypatch.setattr(motion, "_warned", False)
    monkeypatch.delenv("GVE_STEPPER", raising=False)
    assert isinstance(motion.create(3, 1000), PythonMotion)
    assert isinstance(motion.create(3, 1000), PythonMotion)
    err = capsys.readouterr().err
    assert err.count("using the Python twin") == 1


def test_forcing_c_without_it_is_an_error(monkeypatch):
    monkeypatch.setattr(motion, "_c_class", _missing)
    monkeypatch.setenv("GVE_STEPPER", "c")
    with pytest.raises(ImportError):
        motion.create(3, 1000)


def test_forcing_python(monkeypatch):
    monkeypatch.setenv("GVE_STEPPER", "python")
    assert isinstance(motion.create(4, 1000), PythonMotion)
    with pytest.raises(ValueError):
        motion.create(3, 1000, stepper="fortran")
