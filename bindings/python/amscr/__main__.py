"""``python -m amscr ARGS``: the bundled command-line tool, as the ``amscr`` command runs it (for an
environment whose ``bin/`` is not on PATH)."""
import sys

from ._console import main

sys.exit(main())
