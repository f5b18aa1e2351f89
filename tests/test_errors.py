"""The one error hierarchy (swtlab_base.errors): every error class of the project is a
SwtlabError, and the command line tells the user's input (exit 3) from a fault of swtlab
(exit 4) by class, not by name."""

from __future__ import annotations

import ast
import types
from pathlib import Path

import pytest

from swtlab_base.errors import InputError, SwtlabError
from swtlab_cli import exit_codes, main as cli

ROOT = Path(__file__).resolve().parents[1]
#: the installed packages and the repository's second rig
PACKAGES = ("swtlab_base", "ingest", "stable_phase", "fitting", "run_results", "wpm_export",
            "softflow", "terramechanics", "traceability", "sim_gap", "campaign_report",
            "swtlab", "swtlab_cli", "validation")
#: built-in bases a project error must not stand on alone
BUILTIN_ERRORS = {"Exception", "ValueError", "RuntimeError", "LookupError", "KeyError",
                  "TypeError", "OSError"}


def _error_classes() -> dict[str, list[str]]:
    """``module:Class`` -> the names of its bases, for every class of the packages that
    derives from a built-in exception or a class whose name ends in Error."""
    found = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            if "migrations" in path.parts:
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if not isinstance(node, ast.ClassDef):
                    continue
                bases = [b.id if isinstance(b, ast.Name) else ast.unparse(b) for b in node.bases]
                if any(b in BUILTIN_ERRORS or b.endswith(("Error", "Refused", "Claimed"))
                       for b in bases):
                    found[f"{path.relative_to(ROOT)}:{node.name}"] = bases
    return found


def test_every_error_class_of_the_project_stands_on_swtlab_error():
    classes = _error_classes()
    assert len(classes) >= 19  # the classes the hierarchy was made for (issue 39)
    alone = {name: bases for name, bases in classes.items()
             if not set(bases) - BUILTIN_ERRORS}
    assert alone == {"swtlab_base/errors.py:SwtlabError": ["Exception"]}


def test_the_errors_users_cause_are_input_errors_and_keep_their_value_error_base():
    from fitting.errors import TooFewPointsError
    from ingest import IngestError
    from sim_gap.points_csv import PointsFormatError
    from terramechanics.model_file import ModelFileError
    from traceability.database import UnusableDatabase
    from wpm_export.schema import WpmFormatError

    for error in (TooFewPointsError, IngestError, PointsFormatError, ModelFileError,
                  UnusableDatabase, WpmFormatError):
        assert issubclass(error, InputError) and issubclass(error, SwtlabError)
    for error in (TooFewPointsError, PointsFormatError, ModelFileError, WpmFormatError):
        assert issubclass(error, ValueError)  # callers that catch ValueError still do


def _command_raising(monkeypatch, error: BaseException) -> None:
    """``swtlab sim`` replaced by a command that raises ``error``."""
    def register(sub):
        sub.add_parser("sim").set_defaults(func=lambda args: (_ for _ in ()).throw(error))

    monkeypatch.setattr(cli, "command_module", lambda name: types.SimpleNamespace(
        register=register))


def test_an_input_error_a_command_lets_through_exits_3_with_its_own_line(monkeypatch, capsys):
    from terramechanics.model_file import ModelFileError

    _command_raising(monkeypatch, ModelFileError("bad.toml: [soil]: unknown key 'kc'"))
    assert cli.main(["sim"]) == exit_codes.BAD_INPUT
    err = capsys.readouterr().err
    assert err == "swtlab sim: bad.toml: [soil]: unknown key 'kc'\n"


@pytest.mark.parametrize("error", [ZeroDivisionError("injected"), SwtlabError("injected")])
def test_any_other_error_is_internal(monkeypatch, capsys, error):
    _command_raising(monkeypatch, error)
    assert cli.main(["sim"]) == exit_codes.INTERNAL
    assert f"internal error: {type(error).__name__}: injected" in capsys.readouterr().err
