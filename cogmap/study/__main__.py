"""``python -m cogmap.study ARGS`` is ``cogmap reproduce ARGS`` (one-line errors, ``--debug``)."""

import sys

from cogmap.cli import main

if __name__ == "__main__":
    sys.exit(main(["reproduce", *sys.argv[1:]]))
