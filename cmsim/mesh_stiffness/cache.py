"""On-disk cache of expensive per-design results (FE influence-coefficient tables).

Entries are ``.npz`` files named ``<kind>-<key>.npz`` in the cache directory, where the key
is the SHA-256 of a canonical JSON of every input that changes the result (geometry,
material, method parameters and a format version). Writes are atomic (temporary file beside
the target, then :func:`os.replace`), so a crash or a concurrent writer never leaves a
half-written entry; two processes computing the same entry simply both write it.

The directory is ``$CMSIM_CACHE_DIR`` if set, else ``~/.cache/cmsim``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError

__all__ = ["cache_dir", "cache_key", "cache_path", "load_entry", "save_entry",
           "CACHE_ENV_VAR"]

#: Environment variable that overrides the cache directory.
CACHE_ENV_VAR = "CMSIM_CACHE_DIR"


def cache_dir():
    """The cache directory (not created), as a :class:`pathlib.Path`."""
    env = os.environ.get(CACHE_ENV_VAR)
    return Path(env).expanduser() if env else Path.home() / ".cache" / "cmsim"


def _canonical(value):
    """JSON-able canonical form: floats by ``repr`` (exact), tuples as lists, sorted keys."""
    if isinstance(value, dict):
        return {str(k): _canonical(v) for k, v in sorted(value.items())}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            raise ParameterError(f"cache key inputs must be finite, got {v!r}")
        return repr(v)
    if value is None or isinstance(value, str):
        return value
    raise ParameterError(f"cannot build a cache key from a {type(value).__name__}")


def cache_key(kind, inputs):
    """Hex digest (32 characters) identifying ``inputs`` for an entry of ``kind``.

    Parameters
    ----------
    kind : str
        Entry family, e.g. ``"influence"``.
    inputs : dict
        Every input that changes the result (numbers, strings, nested dicts/lists).

    Returns
    -------
    str

    Examples
    --------
    >>> cache_key("x", {"a": 1.0}) == cache_key("x", {"a": 1.0})
    True
    >>> cache_key("x", {"a": 1.0}) == cache_key("x", {"a": 1.0 + 1e-15})
    False
    """
    text = json.dumps({"kind": kind, "inputs": _canonical(inputs)}, sort_keys=True)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]


def cache_path(kind, key):
    """Path of the entry ``kind``/``key``."""
    if not kind.replace("-", "").replace("_", "").isalnum():
        raise ParameterError(f"cache kind must be alphanumeric, got {kind!r}")
    return cache_dir() / f"{kind}-{key}.npz"


def load_entry(kind, key):
    """Arrays and metadata of a cached entry, or ``None`` if absent or unreadable.

    Returns
    -------
    (dict of ndarray, dict) or None
        The arrays and the JSON metadata stored with :func:`save_entry`.
    """
    path = cache_path(kind, key)
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files if k != "__meta__"}
            meta = json.loads(str(z["__meta__"]))
    except (OSError, ValueError, KeyError):
        return None
    return arrays, meta


def save_entry(kind, key, arrays, meta):
    """Write an entry atomically; return its path.

    Parameters
    ----------
    kind, key : str
        From :func:`cache_key`.
    arrays : dict of ndarray
        Numeric arrays to store.
    meta : dict
        JSON-serialisable metadata (inputs, timings, provenance).
    """
    if "__meta__" in arrays:
        raise ParameterError("array name __meta__ is reserved")
    payload = {k: np.asarray(v) for k, v in arrays.items()}
    payload["__meta__"] = np.array(json.dumps(meta, sort_keys=True))
    return atomic_savez(cache_path(kind, key), **payload)
