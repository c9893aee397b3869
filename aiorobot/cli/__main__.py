"""``python -m aiorobot.cli``: the same as the ``aiorobot`` command."""

from __future__ import annotations

import sys

from . import main

sys.exit(main())
