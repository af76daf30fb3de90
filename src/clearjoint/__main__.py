"""Run the command line as ``python -m clearjoint``."""

import sys

if __name__ == "__main__":  # not when a tool or a spawned Dask worker merely imports it
    try:
        from clearjoint.cli import main
    except KeyboardInterrupt:  # Ctrl-C while the libraries load: as main() says it, exit 130
        print("clearjoint: interrupted; nothing written", file=sys.stderr)
        raise SystemExit(130) from None
    raise SystemExit(main())
