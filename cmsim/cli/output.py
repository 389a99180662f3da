"""What commands write besides their result: figures (atomically), and the lines and
warnings that say what a measured record's reader inferred."""

from __future__ import annotations

import io

from cmsim._io import atomic_write_bytes

__all__ = ["save_figure", "inferred_lines", "warn_inferred"]


def save_figure(fig, path):
    """Write the matplotlib figure ``fig`` as PNG at ``path``, atomically."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())


#: What a measured record's reader may infer → (its name in a line, unit, the option that
#: states it instead).
_INFERRED = {"speed_rpm": ("shaft speed", " rpm", "--speed-rpm"),
             "fs_hz": ("sample rate", " Hz", "--fs-hz")}


def inferred_lines(inferred):
    """One line per value a measured record's reader inferred from the signal (its
    ``inferred`` mapping: name → ``{"value", "how"}``), saying from what: compare,
    calibrate and spectrum print them alike."""
    return [f"{_INFERRED.get(k, (k, ''))[0]} inferred from the signal: {v['value']:.6g}"
            f"{_INFERRED.get(k, (k, ''))[1]} ({v['how']})" for k, v in (inferred or {}).items()]


def warn_inferred(args, inferred):
    """Warn through ``args.warn`` about each inferred value, naming the option that states
    it instead (a wrong inference moves every labelled line)."""
    for k, v in (inferred or {}).items():
        what, unit, option = _INFERRED.get(k, (k, "", "it"))
        args.warn(f"{what} {v['value']:.6g}{unit} inferred from the signal ({v['how']}), "
                  f"not stated by the file, metadata.json or an option; give {option} if "
                  f"it is known")
