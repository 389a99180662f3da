"""The ``cmsim`` command line: ``main(argv)``, one module per command, thin over the library.

* :mod:`~cmsim.cli.app` — :func:`main`, :func:`build_parser`: parse, run, print;
  :func:`console`, the console script: :func:`main`, then an exit without teardown;
* :mod:`~cmsim.cli.contract` — the one way the command line validates, names options in
  messages and reports errors (exit 2 bad input, 3 diverged, one line, ``--json``);
* :mod:`~cmsim.cli.options` — the option groups several commands share (rig, the one sampling
  group, mesh, faults, losses, what a measured recording does not state), their defaults
  and ranges from the library;
* one module per command: :mod:`~cmsim.cli.simulate`, :mod:`~cmsim.cli.modes`,
  :mod:`~cmsim.cli.mesh_table`, :mod:`~cmsim.cli.spectrum`, :mod:`~cmsim.cli.sweep`,
  :mod:`~cmsim.cli.dataset`, :mod:`~cmsim.cli.report`, :mod:`~cmsim.cli.evaluate`,
  :mod:`~cmsim.cli.compare`, :mod:`~cmsim.cli.calibrate`, :mod:`~cmsim.cli.import_`,
  :mod:`~cmsim.cli.losses`, each with ``register(sub)``,
  ``run(args)`` and ``text(result)``.
"""

from cmsim.cli.app import build_parser, console, main

__all__ = ["main", "console", "build_parser"]
