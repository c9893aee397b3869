"""``python -m aiorobot.compat script.py [args...]``: as ``aiorobot exec``."""

import sys

from ._run import run_script

sys.exit(run_script(sys.argv[1:], prog="python -m aiorobot.compat"))
