"""Session-wide test settings."""

import pytest


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
