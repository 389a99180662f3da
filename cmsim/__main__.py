"""``python -m cmsim``: the ``cmsim`` command (the same as ``python -m cmsim.cli``)."""

from cmsim.cli.app import console

if __name__ == "__main__":
    console()
