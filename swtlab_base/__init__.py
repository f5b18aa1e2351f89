"""The ground floor every stage of swtlab shares (README, "Layout"): the domain model
(:mod:`swtlab_base.domain`: wheel, soil, test condition, gravity, the results-table schema
and its quantities), atomic file writing (:mod:`swtlab_base.atomic`), strict JSON
(:mod:`swtlab_base.plain_json`), numbers as people read them (:mod:`swtlab_base.rounding`),
order statistics (:mod:`swtlab_base.order_stats`), the cores a process may use
(:mod:`swtlab_base.cores`) and work on a dask cluster (:mod:`swtlab_base.cluster`).

It imports no other package of swtlab: every stage may import it, and nothing here knows
the stages (the import-linter ``layers`` contract in pyproject.toml).
"""
