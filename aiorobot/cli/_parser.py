"""An argparse parser whose errors are one line on stderr (status 2), not usage plus error."""

from __future__ import annotations

import argparse
import math
from typing import NoReturn

__all__ = ["ArgumentParser", "positive_seconds"]


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` that reports a bad argument on a single line."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def positive_seconds(text: str) -> float:
    """argparse ``type=`` for durations: a finite number of seconds greater than zero."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number of seconds such as 3 or 0.5, found {text!r}"
        ) from None
    if not math.isfinite(value) or value <= 0.0:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, found {text!r}")
    return value
