"""The example designs ship in the package: listed, printed, copied, and usable from a wheel."""

import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import ruledmesh
from ruledmesh import bundled
from ruledmesh.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]


def test_repository_examples_folder_is_the_bundled_folder():
    repo = sorted(p.name for p in (ROOT / "examples").iterdir())
    assert repo == sorted(p.name for p in bundled.folder().iterdir())
    assert (ROOT / "examples" / "skew.toml").read_bytes() == bundled.path("skew").read_bytes()
    assert "skew" in ruledmesh.examples() and "lines-file" in ruledmesh.examples()


def test_examples_lists_every_design_with_one_line(capsys):
    assert main(["examples"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == bundled.names()
    for line in lines:
        name, text = line.split(maxsplit=1)
        assert 10 <= len(text) <= 100, (name, text)
    skew = next(line for line in lines if line.startswith("skew "))
    assert "PQ mesh" in skew


def test_printed_example_builds(capsys, tmp_path):
    assert main(["examples", "skew"]) == 0
    text = capsys.readouterr().out
    assert text == (ROOT / "examples" / "skew.toml").read_text()
    (tmp_path / "mine.toml").write_text(text)
    assert main(["build", str(tmp_path / "mine.toml"), "-o", str(tmp_path / "m.obj"), "-q"]) == 0
    assert ruledmesh.load(tmp_path / "m.obj").count_kinds() == ruledmesh.build(text).count_kinds()


def test_copy_brings_the_csv_it_reads(tmp_path, capsys):
    assert main(["examples", "lines-file", "-o", str(tmp_path / "d")]) == 0
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == ["lines-file.toml",
                                                                   "lines-hyperboloid.csv"]
    assert "lines-hyperboloid.csv" in capsys.readouterr().out
    mesh = ruledmesh.build(tmp_path / "d" / "lines-file.toml")
    assert mesh.count_kinds()["quad"] > 0


def test_unknown_example_is_one_line_exit_2(capsys):
    assert main(["examples", "skwe"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'did you mean "skew"' in err


def test_examples_path_falls_back_to_the_bundled_file_only_when_missing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert bundled.resolve("examples/skew.toml") == bundled.path("skew")
    assert bundled.resolve("examples/nothing.toml") == Path("examples/nothing.toml")
    assert bundled.resolve("other/skew.toml") == Path("other/skew.toml")
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "skew.toml").write_text("# mine\n")
    assert bundled.resolve("examples/skew.toml") == Path("examples/skew.toml")


def _help_examples() -> list[list[str]]:
    """The ``ruledmesh ...`` commands the --help texts show, top level first."""
    parser = build_parser()
    sub = next(a for a in parser._actions if a.choices and "build" in a.choices)
    texts = [parser.epilog] + [p.epilog or "" for p in sub.choices.values()]
    commands = []
    for text in texts:
        for line in text.splitlines():
            found = re.search(r"ruledmesh (\S.*?)(\s{2,}|\s+\(|$)", line)
            if found and "<" not in found.group(1):
                commands.append(found.group(1).split())
    # The designer and the Hops server serve until stopped; their own tests cover them.
    return [c for c in commands if c[0] not in ("design", "hops")]


@pytest.fixture(scope="module")
def source_copy(tmp_path_factory):
    """The files a package build reads, copied (the build writes into its source folder)."""
    src = tmp_path_factory.mktemp("source")
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, src / name)
    shutil.copytree(ROOT / "src", src / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    return src


def test_sdist_holds_real_example_files(source_copy, tmp_path):
    import tarfile

    code = ("import sys; from setuptools import build_meta; "
            "print(build_meta.build_sdist(sys.argv[1]))")
    run = subprocess.run([sys.executable, "-c", code, str(tmp_path)], check=False,
                         capture_output=True, text=True, cwd=source_copy, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    with tarfile.open(tmp_path / run.stdout.strip().splitlines()[-1]) as tar:
        members = {Path(m.name).name: m for m in tar.getmembers()
                   if "/src/ruledmesh/examples/" in m.name}
    assert set(members) == {p.name for p in bundled.folder().iterdir()}
    assert all(m.isfile() for m in members.values())


@pytest.fixture(scope="module")
def wheel_install(tmp_path_factory, source_copy):
    """ruledmesh built as a wheel from a copy of the sources and installed into a folder."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = source_copy
    run = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
                          "--no-build-isolation", "-w", str(tmp / "dist"), str(src)],
                         check=False, capture_output=True, text=True, timeout=300)
    if run.returncode != 0:
        pytest.fail(f"pip wheel failed: {run.stderr[-2000:]}")
    wheel = next((tmp / "dist").glob("ruledmesh-*.whl"))
    target = tmp / "site"
    run = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target",
                          str(target), str(wheel)], check=False, capture_output=True, text=True, timeout=300)
    if run.returncode != 0:
        pytest.fail(f"pip install failed: {run.stderr[-2000:]}")
    return wheel, target


def test_wheel_holds_real_example_files(wheel_install):
    wheel, _ = wheel_install
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        skew = zf.read("ruledmesh/examples/skew.toml")
    expected = {f"ruledmesh/examples/{p.name}" for p in bundled.folder().iterdir()}
    assert expected <= names
    assert skew == bundled.path("skew").read_bytes()
    assert wheel.name.startswith(f"ruledmesh-{ruledmesh.__version__}-")


def test_help_examples_work_from_a_wheel_install(wheel_install, tmp_path):
    _, target = wheel_install
    # Numpy paths: the numba kernels would compile again for this install (31 of the test's
    # 46 s), and the suite runs on the kernels of an installed package already (.ci/run
    # installs with pip install ., not in editable mode); what is new here is the bundled files.
    env = {**os.environ, "PYTHONPATH": str(target), "MPLBACKEND": "Agg", "RULEDMESH_KERNELS": "0"}
    where = subprocess.run([sys.executable, "-c", "import ruledmesh; print(ruledmesh.__file__)"],
                           check=False, capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert Path(where.stdout.strip()).is_relative_to(target), where
    # The examples that name a bundled design (examples/NAME.toml) are what a wheel install
    # changes; tests/test_help_examples.py runs every example from the checkout.
    commands = [c for c in _help_examples() if any(a.startswith("examples/") for a in c)]
    assert commands[0] == ["build", "examples/skew.toml", "-o", "skew.obj"]
    assert len(commands) >= 3
    failed = {}
    for args in commands:
        run = subprocess.run([sys.executable, "-m", "ruledmesh", *args], check=False, capture_output=True,
                             text=True, env=env, cwd=tmp_path, timeout=300)
        if run.returncode != 0:
            failed[" ".join(args)] = run.stderr.strip()
    # Every example works (the fabricate example's sheet fits the mesher's panels since the
    # border and crease bands no longer hold 2 m splinters).
    assert not failed, failed
    assert (tmp_path / "skew.obj").is_file() and not (tmp_path / "examples").exists()
