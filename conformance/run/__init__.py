"""Running the suite: the cases selected by ID (selection.py), run against targets into
graded results (runner.py), what a run report says of the run (metadata.py), and which
rules the suite can fail (coverage.py)."""
