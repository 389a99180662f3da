"""A folder of measured records as a dataset (the interface the diagnostics harness reads).

:class:`MeasuredDataset` reads every recording of a folder with :func:`read_record` — the same
reader, the same sample-rate and speed rules as ``cmsim compare`` — and offers ``manifest``,
``record(id)``, ``len`` and iteration, like a generated dataset
(:func:`cmsim.datasets.load`). The answer key (``condition``, ``fault*``) is read for scoring
only, into the manifest columns ``fault_label`` and ``fault_severity`` and
:meth:`MeasuredDataset.answer_key`; the records never hold it.

:func:`data_root` is where the shared measured data sit: ``$CMSIM_DATA`` if set, else
``../shared/datasets`` beside the repository. Nothing is copied into the repository.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from cmsim._io import READ_ERRORS
from cmsim.errors import ParameterError
from cmsim.measured.record import read_record
from cmsim.measured.schema import answer_key, read_metadata

__all__ = ["MeasuredDataset", "load_measured", "data_root", "MEASURED_DATASETS"]

#: Folders of ``../shared/datasets`` scored in the documentation (docs/guide/diagnostics.md).
MEASURED_DATASETS = ("cwru_bearing_12k_de", "mfpt_bearing", "spectraquest_gearbox_gfd")


def data_root():
    """Folder of the shared measured datasets: ``$CMSIM_DATA``, else ``../shared/datasets``
    beside the repository root (may not exist).

    Returns
    -------
    pathlib.Path
    """
    env = os.environ.get("CMSIM_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2].parent / "shared" / "datasets"


class MeasuredDataset:
    """The recordings of one folder, with the harness's dataset interface.

    Parameters
    ----------
    folder : str or pathlib.Path
        Folder with ``metadata.json`` and one signal file per recording.
    trust_metadata : bool
        Read every recording's stated rate and speed unchecked
        (:func:`~cmsim.measured.record.read_record`).

    Attributes
    ----------
    name : str
        Folder name.
    folder : pathlib.Path
    manifest : pandas.DataFrame
        One row per recording: ``record_id``, ``status`` ("ok", or "unreadable" for a
        recording whose file is missing or damaged, or whose stated rate or speed its own
        lines refuse, with the reason in ``error``), ``path``,
        ``fs_hz``, ``speed_rpm``, ``radial_load_n`` (documented or inferred values), and the
        answer key ``fault_label``, ``fault_severity`` (m or NaN) for scoring. One bad
        recording does not make the folder unusable: the others are read.
    assumptions : list of str
        What was not documented and was inferred or assumed (e.g. the sample rate).
    """

    def __init__(self, folder, trust_metadata=False):
        import pandas as pd

        folder = Path(folder)
        if not (folder / "metadata.json").is_file():
            raise ParameterError(f"{folder}: no metadata.json (not a measured dataset folder)",
                                 param="dataset")
        meta = read_metadata(folder)
        self.name = folder.name
        self.folder = folder
        self.assumptions = []
        self._records, self._answers, rows = {}, {}, []
        for r in meta["recordings"]:
            if "file" not in r:
                raise ParameterError(f"{folder}/metadata.json: a recording has no file",
                                     param="dataset")
            try:
                rec = read_record(folder / r["file"], trust_metadata=trust_metadata)
            except READ_ERRORS as exc:     # ParameterError included: named, with the fix
                why = " ".join(str(exc).split()) or type(exc).__name__
                if str(r["file"]) not in why:
                    why = f"record {folder / r['file']}: {type(exc).__name__}: {why}"
                rows.append(_unreadable_row(r, why))
                continue
            rid = rec.record_id
            for k, v in rec.inferred.items():
                self.assumptions.append(f"{rid}: {k} = {v['value']:.6g} inferred ({v['how']})")
            self._records[rid] = rec
            self._answers[rid] = answer_key(r)
            rows.append({"record_id": rid, "status": "ok", "error": None, "path": r["file"],
                         "fs_hz": rec.fs_hz, "speed_rpm": rec.operating_point.speed_rpm,
                         "radial_load_n": rec.operating_point.radial_load_n,
                         "fault_label": self._answers[rid]["fault_label"],
                         "fault_severity": self._answers[rid]["fault_severity"]})
        self.manifest = pd.DataFrame(rows)

    @property
    def unreadable(self):
        """{record_id: why} of the recordings that could not be read."""
        bad = self.manifest[self.manifest["status"] == "unreadable"]
        return dict(zip(bad["record_id"], bad["error"]))

    def __len__(self):
        return len(self._records)

    def __iter__(self):
        return iter(self._records.values())

    def record(self, record_id):
        """The :class:`~cmsim.measured.record.MeasuredRecord` of ``record_id`` (file stem) or
        of a row index.

        Parameters
        ----------
        record_id : str or int
        """
        if isinstance(record_id, (int, np.integer)) and record_id not in self._records:
            record_id = self.manifest["record_id"].iloc[int(record_id)]
        try:
            return self._records[str(record_id)]
        except KeyError:
            raise ParameterError(f"{self.name}: no record {record_id!r}; have "
                                 f"{list(self._records)}", param="record_id") from None

    def answer_key(self, record_id):
        """The answer key of a record (``fault_label``, ``fault_severity``, ``condition``):
        for scoring only.

        Parameters
        ----------
        record_id : str
        """
        return dict(self._answers[str(record_id)])


def _unreadable_row(recording, why):
    """The manifest row of a recording that could not be read (its answer key kept)."""
    key = answer_key(recording)
    return {"record_id": Path(recording["file"]).stem, "status": "unreadable", "error": why,
            "path": recording["file"], "fs_hz": np.nan, "speed_rpm": np.nan,
            "radial_load_n": np.nan, "fault_label": key["fault_label"],
            "fault_severity": key["fault_severity"]}


def load_measured(folder, trust_metadata=False):
    """:class:`MeasuredDataset` of a folder with ``metadata.json``.

    Parameters
    ----------
    folder : str or pathlib.Path
    trust_metadata : bool
        Read every recording's stated rate and speed unchecked.

    Returns
    -------
    MeasuredDataset
    """
    return MeasuredDataset(folder, trust_metadata=trust_metadata)
