"""The settings profiles mean the same in CI as on a desk: Hypothesis loads a profile
of its own when CI is set in the environment, and ours must not inherit from it."""

import json
import os
import subprocess
import sys


def _profiles_under(env: dict[str, str]) -> dict:
    code = ("import json; from conformance.case.settings import PROFILES, run_seed; "
            "print(json.dumps({n: [p.derandomize, p.max_examples, run_seed([n]) is None] "
            "for n, p in PROFILES.items()}))")
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def test_profiles_are_the_same_with_and_without_ci_in_the_environment():
    plain = {k: v for k, v in os.environ.items() if k != "CI"}
    here, in_ci = _profiles_under(plain), _profiles_under({**plain, "CI": "true"})
    assert in_ci == here
    # dev and thorough draw fresh examples (a seed is printed), ci does not
    assert in_ci["dev"][0] is False and in_ci["dev"][2] is False
    assert in_ci["thorough"][0] is False and in_ci["ci"][0] is True and in_ci["ci"][2] is True
