"""``python -m cmsim``: the ``cmsim`` command (the same as ``python -m cmsim.cli``)."""

import sys

from cmsim.cli.app import main

if __name__ == "__main__":
    sys.exit(main())
