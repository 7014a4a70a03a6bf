"""Reports reach the disk whole or not at all, and a run never writes into another run's
folder: a full disk leaves the file as it was (or none), no partial file behind; a run id
taken is refused, at once or later; a fresh id is always a folder of its own."""

from __future__ import annotations

import errno
import json
import os

import pytest

from conformance.reports import files
from conformance.reports.files import ReportNotWritten, RunFolderTaken, claim, release, write_text


def _full(*_: object) -> None:
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_file_is_replaced_whole(tmp_path):
    path = write_text(tmp_path / "results.json", json.dumps({"a": 1}))
    write_text(path, json.dumps({"a": 2}))
    assert json.loads(path.read_text()) == {"a": 2}
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


def test_a_full_disk_leaves_the_file_as_it_was_and_nothing_partial(tmp_path, monkeypatch):
    path = write_text(tmp_path / "results.json", '{"as": "before"}')
    monkeypatch.setattr(files.os, "fsync", _full)
    with pytest.raises(ReportNotWritten, match=r"cannot write .*results.json: No space left"):
        write_text(path, '{"as": "after", "and": "' + "x" * 100_000 + '"}')
    assert json.loads(path.read_text()) == {"as": "before"}
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


def test_a_run_id_taken_is_refused_and_its_folder_left_alone(tmp_path):
    folder = claim(tmp_path, "nightly")
    (folder / "results.json").write_text("{}")
    with pytest.raises(RunFolderTaken, match=r"--run-id nightly: .* exists"):
        claim(tmp_path, "nightly")
    assert (folder / "results.json").read_text() == "{}"


def test_two_runs_with_one_id_at_once_get_it_once(tmp_path):
    claim(tmp_path, "ci-42")                      # the first of the two
    with pytest.raises(RunFolderTaken):
        claim(tmp_path, "ci-42")                  # the second, before the first wrote


def test_a_folder_nothing_was_written_to_is_given_back(tmp_path):
    folder = claim(tmp_path, "refused")
    release(folder)
    assert claim(tmp_path, "refused") == folder


def test_fresh_ids_are_folders_of_their_own(tmp_path):
    assert len({claim(tmp_path) for _ in range(20)}) == 20
