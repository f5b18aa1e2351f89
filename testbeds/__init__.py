"""Testbeds kept in the repository (not installed): generators whose physics is written apart
from the project's, to score its estimators on truths they have never seen. Imported from the
repository root, like the tests."""
