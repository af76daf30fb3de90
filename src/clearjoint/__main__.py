"""Run the command line as ``python -m clearjoint``."""

from clearjoint.cli import main

if __name__ == "__main__":  # not when a tool or a spawned Dask worker merely imports it
    raise SystemExit(main())
