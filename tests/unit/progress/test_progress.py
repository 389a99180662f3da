"""Progress lines of the long silent waits (cmsim.progress; issue 28).

Tier: behaviour (no physics). A stage writes a start line, heartbeat lines at its interval
and an end line with the time taken, all on stderr and none on stdout; ``CMSIM_PROGRESS=0``
silences it; a step that raises ends with "stopped after". The stages of the FE build and of
the numba compile, and the CLI's ``--json`` contract with them, are tested beside their
modules (tests/unit/mesh_stiffness/test_fe_influence.py, tests/cli/test_commands.py).
"""

import time

import pytest

from cmsim import progress
from cmsim.progress import stage


def test_start_heartbeat_and_end_lines_on_stderr_only(capsys):
    with stage("building", interval_s=0.05):
        time.sleep(0.18)
    cap = capsys.readouterr()
    assert cap.out == ""
    lines = cap.err.splitlines()
    assert lines[0] == "cmsim: building..."
    beats = [line for line in lines if "still running" in line]
    assert 1 <= len(beats) <= 4                  # a few lines, not one per call
    assert lines[-1].startswith("cmsim: building: done in ") and lines[-1].endswith(" s")


def test_quick_stage_in_a_log_is_two_lines(capsys, monkeypatch):
    """stderr captured (not a terminal): heartbeats every LOG_INTERVAL_S, so a CI log gets
    the start and end lines of a step shorter than that."""
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 60.0)
    with stage("quick"):
        pass
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2 and lines[0] == "cmsim: quick..." and "done in" in lines[1]


def test_silenced_by_the_environment(capsys, monkeypatch):
    monkeypatch.setenv("CMSIM_PROGRESS", "0")
    with stage("hidden", interval_s=0.01):
        time.sleep(0.05)
    assert capsys.readouterr().err == ""


def test_a_step_that_raises_says_it_stopped(capsys):
    with pytest.raises(KeyboardInterrupt), stage("interrupted step"):
        raise KeyboardInterrupt
    assert "cmsim: interrupted step: stopped after" in capsys.readouterr().err.splitlines()[-1]
