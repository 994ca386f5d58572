"""Allow ``python -m hertzchain.sweep {sweep,plot-sweep} ...``."""

import sys

from .cli import main

sys.exit(main())
