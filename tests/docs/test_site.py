"""The documentation site builds, offline, with every warning an error (issue 28).

Tier: structure. ``mkdocs build --strict`` into a temporary folder, with this checkout first
on the import path (the API pages document this tree). The site must not need the network:
no web fonts or scripts from a CDN in the pages (``theme.font: false``; no plugin that
fetches at build time). The generated pages follow the code: every ``cmsim`` command has its
section in the CLI reference, every part of the package its API page. The build takes
about 15-30 s on 2 cores.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mkdocs", reason="the docs extra: pip install -e '.[docs]'")
pytest.importorskip("material", reason="the docs extra: pip install -e '.[docs]'")
pytest.importorskip("mkdocstrings_handlers.python", reason="the docs extra")

from cmsim.cli.app import build_parser            # noqa: E402
from cmsim.cli.contract import subparsers          # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
#: A page element that loads something from another site when the page is read.
REMOTE = re.compile(r'<(?:link[^>]*href|script[^>]*src|img[^>]*src)="(?:https?:)?//', re.I)


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet",
                           "-f", str(ROOT / "mkdocs.yml"), "-d", str(out)],
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return out


def test_builds_strict_and_reads_offline(site):
    pages = list(site.rglob("*.html"))
    assert (site / "index.html").is_file() and len(pages) > 20
    remote = {str(p.relative_to(site)) for p in pages if REMOTE.search(p.read_text())}
    assert not remote, f"pages that load from the network: {sorted(remote)[:5]}"


def test_cli_reference_is_generated_from_the_parser(site):
    page = (site / "reference" / "cli" / "index.html").read_text()
    for name, sub in subparsers(build_parser()).items():
        assert f"cmsim {name}" in page
        for action in sub._actions:
            for option in action.option_strings:
                assert option in page, f"cmsim {name} {option} missing from the CLI reference"


def test_every_tutorial_and_api_part_is_built(site):
    for md in (ROOT / "docs" / "tutorials").glob("*.md"):
        assert (site / "tutorials" / md.stem / "index.html").is_file()
    api = {p.name for p in (site / "reference" / "api").iterdir()}
    for unit in ("cmsim", "cmsim_dynamics", "cmsim_mesh_stiffness", "cmsim_spectra"):
        assert unit in api
    dynamics = (site / "reference" / "api" / "cmsim_dynamics" / "index.html").read_text()
    assert "simulate" in dynamics and "compile_kernels" in dynamics
