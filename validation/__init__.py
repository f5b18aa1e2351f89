"""Blind checks of the estimators: campaigns generated with hidden truths and run through the
whole chain. These harnesses import the virtual testbed and the estimators alike; no estimator
imports them (checked by the import contracts in pyproject.toml)."""
