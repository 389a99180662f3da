"""``python -m cmsim.cli``: the ``cmsim`` command."""

from cmsim.cli.app import console

console()
