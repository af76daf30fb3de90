"""Run the command line as ``python -m clearjoint``."""

from clearjoint.cli import main

if __name__ == "__main__":  # not when a tool (Sphinx, pkgutil) merely imports the module
    raise SystemExit(main())
