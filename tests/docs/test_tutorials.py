"""The tutorials of the documentation run as written (docs/tutorials/*.md; issue 28).

Tier: examples (as skfem's ``test_examples.py``): the code a reader copies is the code that
runs; there is no second copy of it here. Each tutorial runs in its own empty folder, its
fenced blocks in page order:

* a block with ``title="FILE"`` (any language) is written to FILE, not run;
* a ``console`` block runs each line that starts with ``$ `` (a trailing ``\\`` continues
  it); the other lines are sample output and are not checked. ``cmsim ...`` runs in this
  process (``cmsim.cli.main``, so the numba kernels load once), ``python ...`` in a
  subprocess; ``> FILE`` at the end sends stdout to FILE; ``export NAME=VALUE`` sets the
  variable unless the test already set it (``CMSIM_DATA`` below). Every command must exit 0;
* a ``python`` block runs in one namespace shared by the page's python blocks (as a notebook
  does); its own ``assert`` lines are the tutorial's checks;
* any other block (``text``, ``toml`` without a title, ...) is prose.

A page with ``<!-- tutorial-test: needs-data -->`` reads the shared measured records: it runs
with ``CMSIM_DATA`` set to :func:`cmsim.measured.dataset.data_root` and is skipped when that
folder is absent. The ``datasets`` folder of the repository is linked into the run folder, so
a tutorial names a shipped spec as ``datasets/ci.toml`` as a reader in the repository root
does. Sizes are the tutorials' own: all four take about 1-2 min on 2 cores once the numba
kernels are compiled (the compare against a machine is most of it).
"""

import contextlib
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from cmsim.cli import main
from cmsim.measured.dataset import data_root

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = sorted((ROOT / "docs" / "tutorials").glob("*.md"))
NEEDS_DATA = "<!-- tutorial-test: needs-data -->"

#: A fenced block: opening fence with its info string, body, closing fence of the same indent.
FENCE = re.compile(r"^(?P<indent>[ ]*)```(?P<info>[^\n`]*)\n(?P<body>.*?)^(?P=indent)```[ ]*$",
                   re.MULTILINE | re.DOTALL)


def blocks(text):
    """``[(language, title or None, body)]`` of the page's fenced blocks, in order."""
    out = []
    for m in FENCE.finditer(text):
        info = m.group("info").strip()
        language = info.split()[0] if info else ""
        title = re.search(r'title="([^"]+)"', info)
        indent = len(m.group("indent"))
        body = "\n".join(line[indent:] for line in m.group("body").splitlines())
        out.append((language, title.group(1) if title else None, body + "\n"))
    return out


def commands(body):
    """The ``$ `` lines of a console block, continuation lines joined."""
    cmds, current = [], None
    for line in body.splitlines():
        if current is not None:
            current += " " + line.strip().rstrip("\\").strip()
            if not line.rstrip().endswith("\\"):
                cmds.append(current)
                current = None
        elif line.startswith("$ "):
            text = line[2:].strip()
            if text.endswith("\\"):
                current = text.rstrip("\\").strip()
            else:
                cmds.append(text)
    return cmds


def run_command(command, monkeypatch):
    """Run one console line in the current folder; fail on a non-zero exit status."""
    argv = shlex.split(command)
    out_file = None
    if len(argv) >= 2 and argv[-2] == ">":
        argv, out_file = argv[:-2], argv[-1]
    if argv[0] == "export":
        name, _, value = argv[1].partition("=")
        if name not in os.environ:
            monkeypatch.setenv(name, value)
        return
    if argv[0] == "cmsim":
        sink = open(out_file, "w") if out_file else contextlib.nullcontext()
        with sink as f, (contextlib.redirect_stdout(f) if out_file
                         else contextlib.nullcontext()):
            status = main(argv[1:])
        assert status == 0, f"`{command}` exited with status {status}"
        return
    if argv[0] == "python":
        argv = [sys.executable, *argv[1:]]
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"`{command}` failed:\n{proc.stderr[-2000:]}"
    if out_file:
        Path(out_file).write_text(proc.stdout)


@pytest.mark.parametrize("page", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_runs_as_written(page, tmp_path, monkeypatch):
    text = page.read_text(encoding="utf-8")
    if NEEDS_DATA in text:
        root = data_root()
        if not Path(root).is_dir():
            pytest.skip(f"shared measured data not found ({root}; set CMSIM_DATA)")
        monkeypatch.setenv("CMSIM_DATA", str(root))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "datasets").symlink_to(ROOT / "datasets", target_is_directory=True)
    namespace = {"__name__": f"tutorial_{page.stem.replace('-', '_')}"}
    ran = 0
    for language, title, body in blocks(text):
        if title is not None:
            (tmp_path / title).write_text(body, encoding="utf-8")
        elif language == "console":
            for command in commands(body):
                run_command(command, monkeypatch)
                ran += 1
        elif language == "python":
            exec(compile(body, f"{page.name} (python block)", "exec"), namespace)
            ran += 1
    assert ran, f"{page.name} has no console or python block to run"


def test_blocks_and_commands_parse_as_documented():
    """The extraction rules on a page written for the purpose."""
    page = ('intro\n\n```toml title="a.toml"\nx = 1\n```\n\n```console\n$ cmsim one \\\n'
            '    --two 2\noutput line\n$ python b.py > out.txt\n```\n\n```text\n$ not run\n```\n')
    got = blocks(page)
    assert [(lang, title) for lang, title, _ in got] == [("toml", "a.toml"), ("console", None),
                                                         ("text", None)]
    assert got[0][2] == "x = 1\n"
    assert commands(got[1][2]) == ["cmsim one --two 2", "python b.py > out.txt"]
