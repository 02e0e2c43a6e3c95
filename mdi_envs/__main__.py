"""``python -m mdi_envs``: the ``mdi-envs`` command line (``mdi_envs.cli``).

Run this way, Python puts the current folder first on the import path, so that plug-ins that
are not installed (the benchmarks) are found from the repository's root.
"""

import sys

from mdi_envs.cli import main

sys.exit(main())
