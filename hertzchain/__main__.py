"""Allow ``python -m hertzchain``."""

import sys

from .cli import main

sys.exit(main())
