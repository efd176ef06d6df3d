"""``python -m rocklab ...``: the same as the ``rocklab`` command."""

import sys

from .pipelines.cli import main

if __name__ == "__main__":
    sys.exit(main())
