"""``aiorobot bag convert -i BAG [STORAGE] [-i BAG ...] -o OUTPUT_OPTIONS.yaml``: ``ros2 bag convert``.

The inputs are merged in time order into each bag the output-options YAML lists (rosbag2's
``output_bags``: split by topic, filter, change storage between mcap and sqlite3, compress, cut
into files; see :mod:`aiorobot.bag._convert`). One line per output says what it received; an
output that selected nothing says so. A bad option file or input is one line and status 2,
checked before anything is written.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["add_convert_arguments", "convert_main"]


def add_convert_arguments(sub: Any) -> None:
    conv = sub.add_parser(
        "convert", help="merge, split, filter, re-store or compress bags (ros2 bag convert)",
        description="Convert bags as described by a rosbag2 output-options YAML (top-level 'output_bags': uri, storage_id, "
        "topics / all_topics / regex / exclude_*, max_bagfile_size, max_bagfile_duration, compression_format).")
    conv.add_argument("-i", "--input", dest="inputs", action="append", nargs="+", required=True, metavar=("BAG", "STORAGE"),
                      help="an input bag and, optionally, its storage id (repeat for several: they are merged)")
    conv.add_argument("-o", "--output-options", dest="options", required=True, metavar="YAML",
                      help="rosbag2 output-options file listing the output bags")


def convert_main(args: argparse.Namespace) -> int:
    from aiorobot.bag import BagError, BagReader, convert, read_output_options

    from ._bag_check import usage_error

    def usage(text: str) -> int:
        return usage_error("convert", text)

    inputs = []
    for item in args.inputs:
        if len(item) > 2:
            return usage(f"-i: expected BAG [STORAGE], found {' '.join(item)!r}")
        if len(item) == 2 and item[1] not in ("mcap", "sqlite3"):
            return usage(f"-i {item[0]}: storage id: expected 'mcap' or 'sqlite3', found {item[1]!r}")
        inputs.append(item[0])
    try:
        outputs = read_output_options(args.options)
        for path, item in zip(inputs, args.inputs):
            if len(item) == 2:
                with BagReader(path) as reader:
                    if reader.storage != item[1]:
                        return usage(f"-i {path}: the bag's storage is {reader.storage}, not {item[1]}")
        results = convert(inputs, outputs)
    except BagError as err:
        return usage(str(err))
    for r in results:
        o = r.output
        if not r.topics and not r.skipped:
            print(f"aiorobot bag convert: warning: {o.uri}: the output options select none of the input topics; "
                  f"the bag is empty", file=sys.stderr)
        comp = f", zstd per {o.compression_mode}" if o.compression_mode else "" if o.compression == "none" else f", {o.compression} chunks"
        print(f"{o.uri}: {r.messages} messages on {len(r.topics)} topic(s) in {len(r.files)} {o.storage} file(s){comp}")
        for topic in r.skipped:
            print(f"aiorobot bag convert: warning: {o.uri}: {topic} skipped: its type is unknown and the bag holds no "
                  f"usable definition of it", file=sys.stderr)
    return 0
