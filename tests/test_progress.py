"""Progress: the library reports to a hook and never prints; the CLI draws bars on a terminal only.

The terminal tests give the real command a pseudo-terminal as stderr (what a
user's shell gives it) and read back what tqdm drew there.
"""

from __future__ import annotations

import io
import os
import pty
import re
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ruledmesh.analysis.report import analyze
from ruledmesh.design import build_file
from ruledmesh.progress import SILENT, Progress, Task, TerminalProgress

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


class Recorder(Progress):
    """Keeps every report: (label, total) per task and (label, n, note) per advance."""

    def __init__(self):
        self.tasks, self.steps, self.closed = [], [], []

    def task(self, label, total=None):
        self.tasks.append((label, total))
        rec = self

        class _T(Task):
            def advance(self, n=1, note=None):
                rec.steps.append((label, n, note))

            def close(self):
                rec.closed.append(label)

        return _T()


def test_build_reports_its_stages_in_order_and_closes():
    rec = Recorder()
    build_file(EXAMPLES / "fig5a-transformed-rotational.toml", progress=rec)
    assert rec.tasks == [("build", 2)]                       # catalogue: mesh, transforms
    assert [note for _, _, note in rec.steps if note] == ["mesh", "transforms"]
    assert sum(n for _, n, _ in rec.steps) == 2 and rec.closed == ["build"]
    rec = Recorder()
    built = build_file(EXAMPLES / "skew.toml", progress=rec)
    assert rec.tasks == [("build", 2)]                       # ruled: generators, mesh
    notes = [note for _, _, note in rec.steps if note]
    assert notes[:2] == ["generators", "mesh"]
    # The refinement's meshes, counted, each with its generators (no unit of the bar).
    made = [re.fullmatch(r"mesh (\d+), (\d+) generators", note) for note in notes[2:]]
    assert len(made) >= 2 and all(made)
    assert [int(m.group(1)) for m in made] == list(range(1, len(made) + 1))
    assert len(built.rulings.u) in {int(m.group(2)) for m in made}
    assert all(n == 0 for _, n, note in rec.steps if note and note.startswith("mesh "))


def test_analysis_reports_every_figure(capsys):
    built = build_file(EXAMPLES / "skew.toml")
    rec = Recorder()
    report = analyze(built.mesh, reference=built.reference, progress=rec)
    label, total = rec.tasks[0]
    assert label == "analyse" and total == sum(n for _, n, _ in rec.steps)
    notes = [note for _, _, note in rec.steps if note]
    assert notes[:2] == ["faces", "closeness"] and "circularity" in notes
    assert report["faces"] == built.mesh.n_faces
    assert capsys.readouterr() == ("", "")                  # the library itself never prints


def test_fabricate_reports_each_sheet(tmp_path):
    from ruledmesh.fabricate.output import fabricate

    mesh = build_file(EXAMPLES / "fig5b-torus.toml").mesh
    rec = Recorder()
    summary = fabricate(mesh, tmp_path / "fab", sheet=(3.0, 3.0), dxf=False, progress=rec,
                        nesting="shelf")
    n = summary["sheets"]["count"]
    assert n > 1 and ("sheets", n) in rec.tasks
    assert sum(k for label, k, _ in rec.steps if label == "sheets") == n
    assert sorted(rec.closed) == sorted(label for label, _ in rec.tasks)


def test_silent_and_non_terminal_draw_nothing():
    stream = io.StringIO()
    bar = TerminalProgress(stream=stream)
    assert not bar.enabled                                   # a StringIO is not a terminal
    with bar.task("build", total=3) as task:
        task.advance(note="mesh")
    with SILENT.task("x") as task:
        task.advance()
    assert stream.getvalue() == ""


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_terminal_progress_draws_label_stage_and_count():
    stream = _Tty()
    bar = TerminalProgress(stream=stream)
    assert bar.enabled
    with bar.task("build", total=2) as task:
        task.advance(note="generators")
        task.advance(note="mesh")
        time.sleep(0.7)        # bars redraw at most every 0.2 s; the ticker redraws at 0.5 s
    assert "build (mesh): 100%" in stream.getvalue() and "2/2" in stream.getvalue()
    assert not TerminalProgress(enabled=False, stream=_Tty()).enabled


def _run_on_pty(argv, cwd):
    """Run the CLI with stderr on a pseudo-terminal; returns (exit code, stdout, terminal text)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "ruledmesh.cli", *argv], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    seen = b""
    while True:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:                                  # the child closed its end
                break
            if not chunk:
                break
            seen += chunk
        elif proc.poll() is not None:
            break
    out = proc.stdout.read().decode()
    proc.wait(timeout=60)
    os.close(master)
    return proc.returncode, out, seen.decode(errors="replace")


@pytest.mark.skipif(sys.platform == "win32", reason="needs a pseudo-terminal")
def test_cli_progress_on_a_terminal_only_and_never_with_q_or_json(tmp_path):
    design = str(EXAMPLES / "skew.toml")
    code, out, tty = _run_on_pty(["build", design, "-o", "a.obj"], tmp_path)
    assert code == 0 and out.startswith("wrote a.obj")
    assert "build (" in tty and "analyse (" in tty and "write a.obj" in tty
    code, out, tty = _run_on_pty(["build", design, "-o", "b.obj", "-q"], tmp_path)
    assert code == 0 and out == "" and tty == ""
    code, out, tty = _run_on_pty(["build", design, "-o", "c.obj", "--json"], tmp_path)
    assert code == 0 and out.lstrip().startswith("{") and "%|" not in tty
    import json

    json.loads(out)                                         # stdout is pure JSON
    code, out, tty = _run_on_pty(["analyze", "a.obj", "-q"], tmp_path)
    assert code == 0 and "planarity" in out and tty == ""
    # stderr a pipe (not a terminal): no bar, only the build's warnings.
    proc = subprocess.run([sys.executable, "-m", "ruledmesh.cli", "build", design, "-o", "d.obj"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0 and "%|" not in proc.stderr and "build (" not in proc.stderr
