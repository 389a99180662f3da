"""What commands write besides their result: figures (atomically)."""

from __future__ import annotations

import io

from cmsim._io import atomic_write_bytes

__all__ = ["save_figure"]


def save_figure(fig, path):
    """Write the matplotlib figure ``fig`` as PNG at ``path``, atomically."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())
