"""``python -m rsmhp.report.portability``: the portability drill
(:func:`rsmhp.report.portability.cli.main`)."""

import sys

from rsmhp.report.portability.cli import main

sys.exit(main())
