"""Session-wide test settings."""

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

try:
    import fcntl
except ImportError:                 # not on Windows: no background compile there
    fcntl = None

#: Environment variable naming the lock the background compile of the batch integrator holds
#: (:mod:`tests._warm_kernels`) while it runs.
WARM_LOCK = "CMSIM_TEST_WARM_LOCK"

#: Longest a batched test waits for that compile, s (then it compiles the kernel itself).
WARM_WAIT_S = 900.0


def pytest_configure(config):
    """With ``-n N`` (the controller, before its workers start): compile the batch integrator
    once, in a background process holding a lock its batched tests wait on
    (:mod:`tests._warm_kernels` says why). Without workers, in a worker or without ``fcntl``
    (Windows), nothing."""
    config.addinivalue_line("markers", "batch_kernels: the module integrates runs in batches "
                            "(it waits for the session's background compile of that kernel)")
    if (fcntl is None or hasattr(config, "workerinput")
            or not getattr(config.option, "numprocesses", None)):
        return
    fd, path = tempfile.mkstemp(prefix="cmsim-warm-", suffix=".lock")
    cache = tempfile.mkdtemp(prefix="cmsim-")     # a cache of its own, as fe_cache's
    env = {**os.environ, "CMSIM_CACHE_DIR": cache}
    fcntl.flock(fd, fcntl.LOCK_EX)          # held by the child from here on (inherited)
    config._cmsim_warm = (subprocess.Popen(
        [sys.executable, "-m", "tests._warm_kernels"], cwd=Path(__file__).parents[1], env=env,
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        pass_fds=(fd,)), path, cache)
    os.close(fd)
    os.environ[WARM_LOCK] = path


def pytest_unconfigure(config):
    warm = getattr(config, "_cmsim_warm", None)
    if warm is not None:
        proc, path, cache = warm
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        os.environ.pop(WARM_LOCK, None)
        Path(path).unlink(missing_ok=True)
        shutil.rmtree(cache, ignore_errors=True)


@pytest.fixture(scope="module", autouse=True)
def batch_kernels_compiled(request):
    """A module marked ``batch_kernels`` starts once the session's background compile of the
    batch integrator has ended (at most :data:`WARM_WAIT_S`), so that it loads the kernel
    from the cache instead of compiling it a second time beside it."""
    path = os.environ.get(WARM_LOCK)
    if path is None or request.node.get_closest_marker("batch_kernels") is None:
        return
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        deadline = time.monotonic() + WARM_WAIT_S
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    break
                time.sleep(0.5)
    finally:
        os.close(fd)


#: The integrators every model hands the same numba types (its parameters read-only:
#: :meth:`~cmsim.dynamics._rhs_kernels.KernelParams.frozen`), by module. A second
#: specialisation in a process is a test handing one of them another type (a writeable
#: array): a whole recompile, 107 and 115 s of a cold CI the two times it happened unseen.
ONE_SPECIALISATION = {"cmsim.dynamics._rhs_kernels": ("integrate_jit",),
                      "cmsim.dynamics._batch_kernels": ("integrate_batch_jit",)}


def specialisations(kernels=ONE_SPECIALISATION):
    """``{name: signatures}`` of the ``kernels`` (module -> names) this process has compiled
    or loaded (a module not imported yet has none)."""
    out = {}
    for module, names in kernels.items():
        mod = sys.modules.get(module)
        for name in names:
            out[name] = list(getattr(mod, name).signatures) if mod is not None else []
    return out


@pytest.fixture(autouse=True)
def integrators_compile_once():
    """Fail the test that gives an integrator of :data:`ONE_SPECIALISATION` its second
    numba specialisation in this process, naming both (the tests after it pass)."""
    before = {k: len(v) for k, v in specialisations().items()}
    yield
    for name, sigs in specialisations().items():
        if len(sigs) > max(before[name], 1):
            pytest.fail(f"{name} compiled again for other argument types (the tests' "
                        f"arrays must be the models' types, read-only parameters: "
                        f"KernelParams.frozen): {sigs}", pytrace=False)


@pytest.fixture(scope="session", autouse=True)
def fe_cache(tmp_path_factory):
    """One FE influence-coefficient cache for the whole session, away from the user's.

    The paper gear's tables are built once (about 10 s) and shared by every test module and
    by the ``cmsim`` subprocesses the CLI tests start (they inherit the environment).
    """
    mp = pytest.MonkeyPatch()
    mp.setenv("CMSIM_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cmsim-cache"))
    yield
    mp.undo()
