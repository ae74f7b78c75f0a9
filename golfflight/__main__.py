"""`python -m golfflight` runs the console command."""

import sys

from golfflight.cli import main

sys.exit(main())
