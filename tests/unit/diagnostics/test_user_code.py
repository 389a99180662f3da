"""A user's diagnostic function runs isolated (issue 26): its output, its exit, its errors.

Test tier: behaviour contracts (no physics). What the function prints (``print`` or file
descriptor 1) reaches stderr, never stdout; ``sys.exit`` and any exception become that
record's error with the traceback of the user's frames; Ctrl-C still stops the evaluation;
a record the dataset cannot give is skipped and counted apart from the algorithm's errors.
Records are white noise held in memory.
"""

import math
import os
import sys
import zipfile
from collections.abc import Mapping
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from cmsim.diagnostics import evaluate
from cmsim.diagnostics.user_code import UserError, call_user
from cmsim.frequencies import rig_frequencies
from cmsim.rig import OperatingPoint, Rig


def noisy(signals, fs_hz, operating_point, frequencies):
    print("user print")
    os.write(1, b"user fd 1\n")
    return "healthy"


def leaves(signals, fs_hz, operating_point, frequencies):
    sys.exit(1)


def test_output_goes_to_stderr(capfd):
    answer, error = call_user(noisy, {}, 1.0, None, None)
    assert (answer, error) == ("healthy", None)
    cap = capfd.readouterr()
    assert cap.out == ""
    assert "user print" in cap.err and "user fd 1" in cap.err


def test_sys_exit_is_an_error_with_its_traceback():
    answer, error = call_user(leaves, {}, 1.0, None, None)
    assert answer is None and isinstance(error, UserError)
    assert error.message == "SystemExit: the function called sys.exit(1)"
    assert "in leaves" in error.traceback and "sys.exit(1)" in error.traceback
    assert "call_user" not in error.traceback              # cmsim's frame left out


def test_ctrl_c_is_not_caught():
    def interrupted(*args):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        call_user(interrupted)


class _Broken(Mapping):
    """Signals of a record whose file is cut short."""

    def __getitem__(self, name):
        raise zipfile.BadZipFile("File is not a zip file")

    def __iter__(self):
        return iter(["a"])

    def __len__(self):
        return 1


class _Dataset:
    def __init__(self, n):
        rig = Rig.paper_2016()
        op = OperatingPoint(speed_rpm=1000.0, torque_nm=10.0)
        rng = np.random.default_rng(0)
        self.name = "memory"
        self._records = {}
        for i in range(n):
            signals = _Broken() if i == 1 else {"a": rng.standard_normal(256)}
            self._records[f"r{i}"] = SimpleNamespace(
                record_id=f"r{i}", signals=signals, fs_hz=1000.0, operating_point=op,
                frequencies=rig_frequencies(rig, op),
                labels={"fault_label": "healthy", "fault_severity": math.nan})
        self.manifest = pd.DataFrame({"record_id": list(self._records), "status": "ok"})

    def record(self, rid):
        return self._records[rid]


def test_errors_keep_tracebacks_and_unreadable_records_are_counted_apart(capfd):
    calls = []

    def third_fails(signals, fs_hz, operating_point, frequencies):
        calls.append(1)
        print("working")
        if len(calls) == 3:
            raise ValueError("bad window")
        return "healthy"

    ev = evaluate(_Dataset(5), third_fails)
    m = ev.metrics
    assert (m["n_records"], m["n_scored"], m["n_failed"], m["records_unreadable"]) == \
        (4, 3, 1, 1)
    assert [rid for rid, _ in ev.unreadable] == ["r1"]
    assert "BadZipFile" not in ev.errors.get("r1", "")         # not the algorithm's error
    assert ev.errors == {"r3": "ValueError: bad window"}
    failed = {r.record_id: r for r in ev.records}["r3"]
    assert "in third_fails" in failed.traceback and 'raise ValueError("bad window")' in \
        failed.traceback
    out = ev.to_dict()
    assert out["records"][2]["record_id"] == "r3"
    assert out["records"][2]["traceback"] == failed.traceback
    assert out["unreadable"] == {"r1": "File is not a zip file"}
    assert capfd.readouterr().out == ""


def test_output_of_the_algorithm_module_on_import_goes_to_stderr(tmp_path, capfd):
    from cmsim.diagnostics import load_algorithm

    path = tmp_path / "chatty_module.py"
    path.write_text("import os\nprint('importing')\nos.write(1, b'fd 1 on import\\n')\n\n"
                    "def f(signals, fs_hz, operating_point, frequencies):\n"
                    "    return 'healthy'\n")
    assert callable(load_algorithm(f"{path}:f"))
    cap = capfd.readouterr()
    assert cap.out == "" and "importing" in cap.err and "fd 1 on import" in cap.err


def test_a_function_that_ends_the_process_fails_its_record_when_isolated(capfd):
    """``os._exit`` and a fatal signal cannot be caught: isolated (as ``cmsim evaluate``
    runs it), the function runs in a forked child, and the record it ended fails with how it
    ended while a new child goes on from the next one; cmsim's own process, its answers and
    its stdout are untouched. In this process (the default) a function keeps its state."""
    import faulthandler
    import signal

    seen = []

    def crashes(signals, fs_hz, operating_point, frequencies):
        seen.append(1)
        x = signals["a"]
        if x[0] == _Dataset(5).record("r2").signals["a"][0]:
            os._exit(0)
        if x[0] == _Dataset(5).record("r4").signals["a"][0]:
            faulthandler.disable()          # pytest's dump of the child's crash: noise here
            os.kill(os.getpid(), signal.SIGSEGV)
        print("answered")
        return "healthy"

    ev = evaluate(_Dataset(5), crashes, isolated=True)
    assert ev.errors == {"r2": "ProcessEnded: the function ended the process (exit status 0)",
                         "r4": "ProcessEnded: the function ended the process (killed by "
                               "SIGSEGV)"}
    assert [r.record_id for r in ev.records] == ["r0", "r2", "r3", "r4"]   # r1 unreadable
    assert [rid for rid, _ in ev.unreadable] == ["r1"]
    assert ev.metrics["n_scored"] == 2 and ev.metrics["n_failed"] == 2
    assert seen == []                       # it ran in the children
    cap = capfd.readouterr()
    assert cap.out == "" and cap.err.count("answered") == 2

    def counts(signals, fs_hz, operating_point, frequencies):
        seen.append(1)
        return "healthy"

    evaluate(_Dataset(5), counts)
    assert len(seen) == 4                   # in this process by default
