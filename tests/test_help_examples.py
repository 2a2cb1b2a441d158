"""Every example the help and the README print runs as printed, and help lists them one per line.

The examples run from a temporary folder holding a copy of ``examples/`` and
the ``skew.obj`` that the README's quick start builds, the way a user who
just followed the README would type them.
"""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest

from ruledmesh.cli import COMMANDS, build_parser, main

ROOT = Path(__file__).resolve().parents[1]

# `ruledmesh design` and `ruledmesh hops` serve until interrupted; their own tests start them
# (tests/test_designer*.py, tests/test_hops.py), so their examples are only checked to parse.
SERVES = ("design", "hops")


def _subparsers():
    parser = build_parser()
    action = next(a for a in parser._actions if a.dest == "command")
    return parser, action.choices


def help_examples() -> list[tuple[str, str]]:
    """(where, command line) of every example line in ``--help`` output."""
    parser, subs = _subparsers()
    out = []
    for where, text in [("ruledmesh --help", parser.format_help()),
                        *((f"ruledmesh {n} --help", p.format_help()) for n, p in subs.items())]:
        for line in text.splitlines():
            m = re.match(r"^\s+(ruledmesh\s.*?)(\s{2,}.*)?$", line)
            if m and "<" not in m.group(1):
                out.append((where, m.group(1).strip()))
    return out


def readme_examples() -> list[tuple[str, str]]:
    """(where, command line) of every ``ruledmesh ...`` command in the README's code blocks."""
    out = []
    for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines():
        if not line.startswith("    "):
            continue
        for part in line.split("&&"):
            part = part.strip()
            if part.startswith("ruledmesh ") and not re.search(r"\b[A-Z]{3,}\b", part):
                out.append(("README.md", part))
    return out


EXAMPLES = sorted(set(help_examples() + readme_examples()), key=lambda e: (e[0], e[1]))


def test_every_subcommand_has_examples_one_per_line():
    _, subs = _subparsers()
    # One subcommand per module in COMMANDS (the blender module's is called blender-addon).
    assert len(subs) == len(COMMANDS) and set(COMMANDS) - {"blender"} <= set(subs)
    for name, parser in subs.items():
        text = parser.format_help()
        lines = [ln.strip() for ln in text.splitlines()]
        examples = [ln for ln in lines if ln.startswith(f"ruledmesh {name} ")]
        assert examples, f"ruledmesh {name} --help shows no example"
        # one per line: no second command on an example's line
        assert all(ln.count("ruledmesh ") == 1 for ln in examples), examples


def test_examples_found():
    assert len(help_examples()) >= 15 and readme_examples()


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("examples-run")
    shutil.copytree(ROOT / "examples", d / "examples")
    return d


@pytest.mark.parametrize("where, line", EXAMPLES, ids=[f"{w}: {c}" for w, c in EXAMPLES])
def test_example_runs_as_printed(workdir, monkeypatch, capsys, where, line):
    monkeypatch.chdir(workdir)
    if not (workdir / "skew.obj").exists():
        assert main(["build", "examples/skew.toml", "-o", "skew.obj", "-q"]) == 0
    argv = shlex.split(line)[1:]
    if argv[0] in SERVES:
        args = build_parser().parse_args(argv)
        assert args.run is not None
        return
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 0, f"{where}: `{line}` exited {code}: {err}"
