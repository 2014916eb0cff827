"""Entry point of the PyInstaller app (``packaging/qtanimator.spec``): the ``qtanimator`` command."""

import sys

from qtanimator.cli import main

if __name__ == "__main__":
    sys.exit(main())
