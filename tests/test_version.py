"""The version comes from one place (pyproject.toml) and each one has its CHANGELOG entry."""

from __future__ import annotations

import importlib.metadata
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_installed_version_is_pyprojects_and_the_newest_changelog_entry():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    # the newest released entry; "## Unreleased" or "## X.Y.Z (unreleased)" above it collects
    # changes until the release
    newest = re.search(r"^## (?!Unreleased)(\S+)(?!.*\(unreleased\))",
                       (ROOT / "CHANGELOG.md").read_text(), re.M).group(1)
    assert importlib.metadata.version("swtlab") == declared == newest
