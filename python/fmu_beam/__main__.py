"""`python -m fmu_beam ...`: the `fmu-beam` command."""

import sys

from fmu_beam import main

sys.exit(main())
