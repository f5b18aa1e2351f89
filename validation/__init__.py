"""Blind checks of the estimators: campaigns generated with hidden truths and run through the
whole chain. These harnesses import the virtual testbed and the estimators alike; no estimator
imports them (checked by the import contracts in pyproject.toml). ``validation.second_rig`` is a
second raw-run generator written apart from the virtual testbed (docs/second-rig.md)."""
