"""``python -m zenav`` is the ``zenav`` command."""

from zenav.cli import main

raise SystemExit(main())
