"""An argparse parser whose errors are one line on stderr (status 2), not usage plus error."""

from __future__ import annotations

import argparse
import math
import re
from typing import NoReturn

__all__ = ["ArgumentParser", "accept_negative_number_lists", "positive_seconds", "transport_name"]

_NUMBER = r"(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: what argparse's own test for a negative number (``-1``, ``-.5``) misses: lists such as ``-0.55,-0.55``
#: and ``-1,0;2,1.57``, separated by commas, semicolons or spaces
_NEGATIVE_NUMBER_LIST = re.compile(rf"^-{_NUMBER}(?:\s*[,;]?\s*-?{_NUMBER})*\s*;?\s*$")


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` that reports a bad argument on a single line."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def accept_negative_number_lists(parser: argparse.ArgumentParser) -> None:
    """Let an option's value start with a minus sign: ``--start -1,-2,0``, ``--waypoints "-0.55,-0.55"``.

    argparse takes ``-1`` and ``-.5`` for values but anything else that starts with ``-`` for an
    option, so ``--waypoints -0.55,-0.55`` failed with "expected one argument". ``parser`` must
    have no option that itself looks like a negative number (argparse's own rule).
    """
    parser._negative_number_matcher = _NEGATIVE_NUMBER_LIST  # type: ignore[attr-defined]


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


def transport_name(text: str) -> str:
    """argparse ``type=`` for ``--transport``: a name in the transport registry (``local``, ``zenoh``
    and whatever an installed package registered), asked when the option is used, not listed here."""
    from .._core._transport import transport_names

    names = transport_names()
    if text not in names:
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(names)}, found {text!r}")
    return text
