"""A run's rig read back from its meta: the same value, parsed once.

Tier: same-code regression guard (issue 27: every dataset record reads its rig's bearing
names, and parsing a rig field by field cost ~3 ms).
"""

import numpy as np

import cmsim
from cmsim.rig import Rig
from cmsim.run import Run


def test_run_rig_is_the_rig_of_its_meta_and_parsed_once():
    rig = cmsim.Rig.paper_2016()
    meta = {"rig": rig.to_dict(), "fs_hz": 10.0}
    a = Run(np.arange(3) / 10.0, {"x_1b1": np.zeros(3)}, meta)
    b = Run(np.arange(3) / 10.0, {"x_1b1": np.ones(3)}, {**meta, "rig": rig.to_dict()})
    assert a.rig == rig == Rig.from_dict(meta["rig"])
    assert b.rig is a.rig                          # an equal meta rig: the parsed value again
    other = cmsim.Rig.paper_2016().to_dict()
    other["name"] = "another"
    assert Run(a.t, a.signals, {**meta, "rig": other}).rig.name == "another"
    assert Run(a.t, a.signals, {"fs_hz": 10.0}).rig is None
