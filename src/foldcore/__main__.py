"""``python -m foldcore …`` runs the command-line tool (same as ``foldcore …``)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
