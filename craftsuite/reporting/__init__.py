"""Reports of student runs, one concept a module.

* ``board``: a directory's runs read as entries (a task, world, method and setting each),
  their metrics, the aggregates across tasks and the verdicts that compare two entries;
* ``sources``: a run directory as the reports find it: its students, suite and sessions;
* ``pages``: Markdown and CSV rendered from entries (a leaderboard, a results page);
* ``plots``: learning curves and performance profiles drawn from entries.
"""
