"""``python -m aiorobot.bench latency ...``: the same as ``aiorobot bench latency ...``."""

from __future__ import annotations

import sys

if __name__ == "__main__":
    from aiorobot.cli import main

    sys.exit(main(["bench", *sys.argv[1:]]))
