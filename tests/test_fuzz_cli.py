"""A fuzz campaign through the command line (docs/robustness.md, "Command-line campaign").

Inputs: every bundled example with random mutations (a number, a string or a
value replaced by junk, a line deleted, doubled or swapped, the file cut short,
an unknown key), garbage TOML (random bytes, token soup, deep nesting, control
characters), and special files (devices, pipes, folders, dangling links).  The
campaign is seeded, so a failure replays; ``FUZZ_CLI_SCALE=10`` runs ten times
as many cases.

For every input ``ruledmesh build`` (and ``analyze`` for the special files):

* exits 0 or 2, never 3 (internal error) and never with a traceback;
* on exit 2 prints exactly one printable line ``ruledmesh: error: ...`` of at
  most ~2000 characters and writes no file;
* on exit 0 writes a mesh with faces and finite coordinates, and every line on
  stderr is a ``warning:`` of its own (no raw numpy warnings).

The examples are shrunk first (counts and rows capped, §4.3 designs unrefined) so
that a case costs a tenth of a second; a mutation may still raise them, up to the caps of the design
layer.
"""

from __future__ import annotations

import os
import random
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from ruledmesh.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
SCALE = int(os.environ.get("FUZZ_CLI_SCALE", "1"))
MUTATIONS_PER_EXAMPLE = 12 * SCALE
GARBAGE_CASES = 100 * SCALE

NUMBERS = ["0", "-0.0", "1", "-1", "3", "0.5", "1e308", "-1e308", "5e-324", "1e30", "-1e-30",
           "1e-12", "nan", "inf", "-inf", "123456789", "2.0e2", "7"]
STRINGS = ['""', '"x"', '"' + "y" * 5000 + '"', '"a\\nb"', '"\\u202e"', '"line"', '"pq"',
           '"hybrid"', '"/dev/zero"', '"examples/skew.toml"', '"\\u0000"']
VALUES = ["true", "[]", "[[1, 2], [3]]", "{a = 1}", "[1, 2, 3]", "[[0, 0, 0], [0, 0, 0]]",
          '"' + "\\n" * 50 + '"']

_CAPS = [(r"^(count\s*=\s*)(\d+)", 12), (r"^(rows\s*=\s*)(\d+)", 6), (r"^(u\s*=\s*)(\d+)", 8),
         (r"^(v\s*=\s*)(\d+)", 6), (r"^(divisions\s*=\s*)(\d+)", 4)]


def shrink(text: str) -> str:
    """The example with its counts capped, and a §4.3 design unrefined (the refinement weighs
    a dozen meshes or more: test_fuzz.py fuzzes it), so a build costs little."""
    for pattern, cap in _CAPS:
        text = re.sub(pattern, lambda m, c=cap: m.group(1) + str(min(int(m.group(2)), c)),
                      text, flags=re.MULTILINE)
    if "[rulings]" in text and not re.search(r'^method\s*=\s*"hybrid"', text, flags=re.MULTILINE):
        text = re.sub(r"^\[mesh\]$", "[mesh]\nrefine = false", text, count=1, flags=re.MULTILINE)
    return text


def mutate(text: str, rng: random.Random) -> str:
    """One random mutation of design text."""
    lines = text.splitlines()
    kind = rng.choice(["number", "number", "number", "string", "value", "delete", "double",
                       "swap", "cut", "key", "bytes"])
    if kind == "number":
        spans = [m.span() for m in re.finditer(r"(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?", text)]
        if spans:
            a, b = rng.choice(spans)
            return text[:a] + rng.choice(NUMBERS) + text[b:]
    if kind == "string":
        spans = [m.span() for m in re.finditer(r'"[^"\n]*"', text)]
        if spans:
            a, b = rng.choice(spans)
            return text[:a] + rng.choice(STRINGS) + text[b:]
    if kind == "value":
        spans = [m.span(1) for m in re.finditer(r"=\s*(\S[^\n#]*)", text)]
        if spans:
            a, b = rng.choice(spans)
            return text[:a] + rng.choice(VALUES) + text[b:]
    if kind in ("delete", "double", "swap") and len(lines) > 2:
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        if kind == "delete":
            del lines[i]
        elif kind == "double":
            lines.insert(i, lines[i])
        else:
            lines[i], lines[j] = lines[j], lines[i]
        return "\n".join(lines) + "\n"
    if kind == "cut":
        return text[:rng.randrange(len(text))]
    if kind == "key":
        heads = [k for k, ln in enumerate(lines) if ln.startswith("[")] or [0]
        lines.insert(rng.choice(heads) + 1, rng.choice(["zz = 1", "count  = 3", "kind = 3",
                                                        "\u202e = 1", '"a\\nb" = 2']))
        return "\n".join(lines) + "\n"
    k = rng.randrange(len(text) + 1)
    return text[:k] + bytes(rng.randrange(256) for _ in range(8)).decode("latin-1") + text[k:]


def garbage(rng: random.Random) -> bytes:
    """Random bytes, TOML-like token soup, deep nesting or control characters."""
    kind = rng.randrange(5)
    if kind == 0:
        return bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400)))
    if kind == 1:
        tokens = ["[", "]", "[[", "]]", "{", "}", "=", ",", '"', "\n", "a", "b.c", "1", "1e9",
                  "true", "#", " ", "'''", "mesh", "rulings", "surface", "kind", "lines"]
        return "".join(rng.choice(tokens) for _ in range(rng.randrange(1, 200))).encode()
    if kind == 2:
        depth = rng.choice([50, 300, 1200, 5000])
        opener, closer = rng.choice([("[", "]"), ("{a = ", "}")])
        return ("x = " + opener * depth + "1" * (opener == "{a = ") + closer * depth).encode()
    if kind == 3:
        key = "".join(chr(rng.choice([0x0A, 0x1B, 0x202E, 0x07, 0x61, 0x2028]))
                      for _ in range(30))
        return f'[surface]\nkind = "{key}"\n["{key}"]\nx = 1\n'.encode("unicode_escape")
    size = rng.choice([10, 10_000, 200_000])
    return (f'[surface]\nkind = "{"k" * size}"\n').encode()


def check_outcome(code: int, out: str, err: str, target: Path) -> str:
    """Assert the campaign's properties; return the outcome's name for the tally."""
    assert code in (0, 2), (code, err[-2000:])
    assert "Traceback" not in err and "internal error" not in err, err[-2000:]
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1, err[-2000:]
        assert lines[0].startswith("ruledmesh: error: ") and lines[0].isprintable(), lines[0]
        assert len(lines[0]) <= 2100, len(lines[0])
        assert not target.exists()
        return "refused"
    assert all(ln.startswith("warning: ") for ln in err.splitlines()), err[-2000:]
    from ruledmesh.io import load

    mesh = load(target)
    assert mesh.n_faces > 0 and np.all(np.isfinite(mesh.vertices))
    target.unlink()
    return "built, warned" if err else "built"


def run_build(tmp_path: Path, capsys: pytest.CaptureFixture[str], data: bytes,
              name: str) -> str:
    design = tmp_path / name
    design.write_bytes(data)
    target = tmp_path / "out.obj"
    code = main(["build", str(design), "-o", str(target)])
    out, err = capsys.readouterr()
    return check_outcome(code, out, err, target)


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_mutated_examples(example: Path, tmp_path: Path,
                          capsys: pytest.CaptureFixture[str]) -> None:
    rng = random.Random(f"ruledmesh-cli-{example.stem}")
    base = shrink(example.read_text(encoding="utf-8"))
    if (example.parent / "lines-hyperboloid.csv").exists():
        (tmp_path / "lines-hyperboloid.csv").write_bytes(
            (example.parent / "lines-hyperboloid.csv").read_bytes())
    tally = Counter(run_build(tmp_path, capsys, mutate(base, rng).encode("utf-8", "replace"),
                              example.name) for _ in range(MUTATIONS_PER_EXAMPLE))
    assert sum(tally.values()) == MUTATIONS_PER_EXAMPLE


def test_garbage_toml(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = random.Random("ruledmesh-cli-garbage")
    tally = Counter(run_build(tmp_path, capsys, garbage(rng), "garbage.toml")
                    for _ in range(GARBAGE_CASES))
    assert tally["refused"] == GARBAGE_CASES, tally   # nothing in there is a design


def _special_files(tmp_path: Path) -> dict[str, Path]:
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    (tmp_path / "folder.toml").mkdir()
    (tmp_path / "dangling.toml").symlink_to(tmp_path / "nowhere.toml")
    (tmp_path / "loop.toml").symlink_to(tmp_path / "loop.toml")
    return {"/dev/zero": Path("/dev/zero"), "/dev/null": Path("/dev/null"),
            "/dev/urandom": Path("/dev/urandom"), "fifo": fifo, "folder": tmp_path / "folder.toml",
            "dangling link": tmp_path / "dangling.toml", "link loop": tmp_path / "loop.toml",
            "/proc/self/status": Path("/proc/self/status")}


@pytest.mark.parametrize("command", ["build", "analyze"])
def test_special_files(tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    for name, path in _special_files(tmp_path).items():
        target = tmp_path / "out.obj"
        argv = [command, str(path)] + (["-o", str(target)] if command == "build" else [])
        code = main(argv)
        out, err = capsys.readouterr()
        assert check_outcome(code, out, err, target) == "refused", name


def test_special_files_as_rulings_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for name, path in _special_files(tmp_path).items():
        text = f'[rulings]\nfile = "{path}"\n[mesh]\nrows = 4\n'
        outcome = run_build(tmp_path, capsys, text.encode(), "lines.toml")
        assert outcome == "refused", name
