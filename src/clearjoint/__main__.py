"""Run the command line as ``python -m clearjoint``."""

from clearjoint.cli import main

if __name__ == "__main__":  # not when a spawned worker (a Dask LocalCluster's) re-imports it
    raise SystemExit(main())
