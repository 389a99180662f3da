"""The documentation's first page gives the README's two commands unchanged (issue 28).

Tier: structure. The README must start with the install-and-run command and the test
command (CI runs them); docs/getting-started.md shows the same block, character for
character, so the two cannot drift apart.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BASH = re.compile(r"^```bash\n(.*?)^```", re.MULTILINE | re.DOTALL)


def first_bash_block(path):
    match = BASH.search(path.read_text(encoding="utf-8"))
    assert match, f"{path.name} has no ```bash block"
    return match.group(1)


def test_getting_started_has_the_readme_commands():
    readme = first_bash_block(ROOT / "README.md")
    lines = readme.splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("python3 -m venv .venv && .venv/bin/pip install -e \".[test]\"")
    assert lines[1].startswith(".venv/bin/python -m pytest")
    assert first_bash_block(ROOT / "docs" / "getting-started.md") == readme
