"""Run the command line as ``python -m clearjoint``."""

from clearjoint.cli import main

raise SystemExit(main())
