"""``python -m jik``: the ``jik`` command."""

from jik.cli import main

raise SystemExit(main())
