"""One option set: every subcommand that writes reports (the run, diff, host and the
gates) takes --report-dir, --run-id, --junitxml, --no-reports, -q and -v with the same
defaults, and --seed where it draws at random (a fresh seed by default, printed and
recorded); every job takes -q, -v and --color, the long ones --seconds, those that run
cases --cases and --exclude, those that run things side by side -j; a shared option says
the same on every subcommand (one parent parser); every option says what it does; diff's
reports say what a run's say."""

from __future__ import annotations

import html
import json
import re
import shlex

import pytest

from conformance.cli import main
from conformance.cli.usage import Parser
from conformance.reports.html import render_html
from tests.conformance.reports.toy import toy_run

#: a subcommand that writes reports -> the least it needs on its command line
WRITERS = {"run": ["--target", "emu:GVE84-100"],
           "diff": ["--target", "emu:GVE84-100"],
           "host": ["--profile", "GVE84-100", "--", "true", "{port}"],
           "mutation": [], "fairness": [], "corpus": []}
COMMON = ("report_dir", "run_id", "no_reports", "junitxml", "quiet", "verbose")


class _Parsed(Exception):
    """Raised in place of parsing: the parser and what it made of the arguments."""


@pytest.fixture
def parsed(monkeypatch, tmp_path):
    """``parsed(argv)``: the parser a subcommand builds and its namespace for ``argv``."""
    monkeypatch.chdir(tmp_path)
    real = Parser.parse_args

    def spy(self, args=None, namespace=None):
        raise _Parsed(self, real(self, args, namespace))

    monkeypatch.setattr(Parser, "parse_args", spy)

    def run(argv: list[str]):
        with pytest.raises(_Parsed) as got:
            main(argv)
        return got.value.args
    return run


def test_every_report_writer_takes_the_same_options_with_the_same_defaults(parsed):
    defaults = {}
    for sub, least in WRITERS.items():
        _, args = parsed([sub, *least])
        defaults[sub] = {name: getattr(args, name) for name in COMMON}
        _, args = parsed([sub, "--report-dir", "r", "--run-id", "x", "--junitxml", "j.xml",
                          "--no-reports", "-q", *least])
        assert (args.report_dir, args.run_id, args.junitxml, args.no_reports, args.quiet) \
            == ("r", "x", "j.xml", True, True), sub
    assert all(d == defaults["run"] for d in defaults.values()), defaults


def test_the_seed_defaults_alike_where_a_job_draws_at_random(parsed):
    for sub in ("run", "diff"):
        _, args = parsed([sub, *WRITERS[sub]])
        assert args.seed is None                        # a fresh one is drawn
        _, args = parsed([sub, "--seed", "7", *WRITERS[sub]])
        assert args.seed == 7
    parser, _ = parsed(["host", *WRITERS["host"]])
    assert "--seed" not in parser._option_string_actions    # host draws nothing at random


@pytest.mark.parametrize("sub", ["mutation", "fairness", "replay"])
def test_the_other_jobs_take_quiet_and_verbose(sub, parsed):
    least = {"replay": ["t.gvt", "--target", "emu:GVE84-100"]}.get(sub, [])
    for flag, name in (("-q", "quiet"), ("-v", "verbose")):
        _, args = parsed([sub, *least, flag])
        assert getattr(args, name) is True


@pytest.mark.parametrize("sub", ["run", "diff", "host", "mutation", "fairness", "corpus",
                                 "replay", "ports"])
def test_every_option_says_what_it_does(sub, parsed):
    least = {"replay": ["t.gvt", "--target", "emu:GVE84-100"], **WRITERS}.get(sub, [])
    parser, _ = parsed([sub, *least])
    silent = [a.option_strings or a.dest for a in parser._actions if not a.help]
    assert silent == [], sub


def test_diff_s_reports_say_what_a_run_s_say(tmp_path, capsys):
    assert main(["diff", "--target", "emu:GVE84-100", "--examples", "3", "--no-probes",
                 "--report-dir", str(tmp_path), "--run-id", "d"]) == 0
    out = capsys.readouterr().out
    meta = json.loads((tmp_path / "d" / "results.json").read_text())["meta"]
    printed = int(re.search(r"seed (\d+)", out).group(1))
    assert meta["seed"] == printed                      # a fresh seed, printed and kept
    assert meta["started"] and meta["finished"] >= meta["started"]
    assert meta["command"][:3] == ["diff", "--target", "emu:GVE84-100"]
    (target,) = meta["targets"]
    assert target["profile"] == "GVE84-100" and target["spec"] == "emu:GVE84-100"
    assert meta["job_flags"]["--seed"] == printed
    page = (tmp_path / "d" / "report.html").read_text()
    assert "derandomized" not in page


def test_the_report_s_command_keeps_its_quoting():
    run = toy_run()
    run.meta.command = ["--target", "exec:./clone-sim --pty", "--profile", "GVE84-100"]
    page = render_html(run)
    row = re.search(r"<th>command</th><td>([^<]*)</td>", page).group(1)
    # a shell given the row runs the same command: the exec: target one argument
    assert shlex.split(html.unescape(row)) == ["gve-conformance", *run.meta.command]


#: every subcommand that runs a job -> the least it needs on its command line
JOBS = {**WRITERS, "ports": [],
        "replay": ["fixtures/transcripts/g1-checksum-mode.gvt", "--target", "emu:GVE84-100"]}
#: those that run several things side by side
PARALLEL = ("run", "host", "mutation", "fairness", "corpus")
#: those that run the catalogue's cases
CASES = ("run", "mutation", "fairness")
#: the long jobs: a time limit (diff: how long it searches)
LONG = ("diff", "mutation", "fairness", "corpus")
#: the options whose help is the same wherever they are (the others say what they do on
#: each job: -v, --jobs, --seed, --seconds)
SAME_HELP = ("--report-dir", "--run-id", "--no-reports", "--junitxml", "--accept-incomplete",
             "--quiet", "--color", "--cases", "--exclude")


def test_every_job_takes_color_and_the_parallel_ones_j(parsed):
    for sub, least in JOBS.items():
        _, args = parsed([sub, *least])
        assert args.color == "auto", sub
        _, args = parsed([sub, "--color", "never", *least])
        assert args.color == "never", sub
    for sub in PARALLEL:
        _, args = parsed([sub, "-j", "2", *JOBS[sub]])
        assert args.jobs == 2, sub


def test_cases_where_cases_run_and_a_time_limit_on_the_long_jobs(parsed):
    for sub in CASES:
        _, args = parsed([sub, "--cases", "5.*", "--exclude", "5.errors.busy", *JOBS[sub]])
        assert (args.cases, args.exclude) == (["5.*"], ["5.errors.busy"]), sub
    for sub in LONG:
        _, args = parsed([sub, "--seconds", "2.5", *JOBS[sub]])
        assert args.seconds == 2.5, sub


def test_a_shared_option_says_the_same_on_every_subcommand(parsed):
    helps: dict[str, set[str]] = {}
    for sub, least in JOBS.items():
        parser, _ = parsed([sub, *least])
        for option in SAME_HELP:
            action = parser._option_string_actions.get(option)
            if action is not None:
                helps.setdefault(option, set()).add(action.help)
    assert set(helps) == set(SAME_HELP)
    assert {o: h for o, h in helps.items() if len(h) > 1} == {}
