"""``python -m cmsim.cli``: the ``cmsim`` command."""

import sys

from cmsim.cli.app import main

sys.exit(main())
