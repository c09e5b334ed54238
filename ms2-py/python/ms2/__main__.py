"""``python -m ms2``: the ``ms2`` command line (see :mod:`ms2.cli`)."""

from .cli import main

raise SystemExit(main())
