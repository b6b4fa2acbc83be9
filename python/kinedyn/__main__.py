"""`python -m kinedyn ...` is the `kinedyn` command."""

import sys

from .cli import main

sys.exit(main())
