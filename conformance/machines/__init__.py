"""Stateful Hypothesis machines, each run as a case with its own abstract model."""
