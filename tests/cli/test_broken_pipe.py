"""``cmsim ... | head``: a reader that closes stdout early ends the command quietly.

Tier: behaviour (a subprocess, as a shell pipe runs it). The read end of stdout is closed
before the command writes its result, so the write always fails: the status is 141 (what a
Unix filter killed by SIGPIPE gives) and stderr holds the command's warnings only, no
traceback. A cheap command (``import`` of a one-file folder) keeps it short.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cmsim.cli.app import BROKEN_PIPE_STATUS

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("json_out", [False, True])
def test_closed_stdout_exits_quietly(tmp_path, json_out):
    np.savez(tmp_path / "a.npz", DE=np.random.default_rng(0).standard_normal(4000))
    argv = [sys.executable, "-m", "cmsim", "import", str(tmp_path), "--fs-hz", "12000",
            "--speed-rpm", "1797", "--unit", "g"] + (["--json"] if json_out else [])
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == BROKEN_PIPE_STATUS == 141
    assert "Traceback" not in err and "BrokenPipe" not in err and "error" not in err
    assert (tmp_path / "metadata.json").is_file()          # the command did its work
