"""``python -m bioflex_jsb.cli``: same as the ``bioflex-jsb`` command."""

import sys

from bioflex_jsb.cli import main

sys.exit(main())
