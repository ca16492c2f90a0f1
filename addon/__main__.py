"""``python -m rigger rig|batch|methods``: see :mod:`rigger.cli`."""
import sys

from .cli import main

sys.exit(main())
