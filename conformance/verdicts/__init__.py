"""Verdicts and what explains them: a check (check.py), the verdicts and their grading
from the spec's tags (verdict.py), why a case got its verdict (explain.py), why results
were not tested (untested.py), and the one way what a target sent is shown (quoting.py)."""
