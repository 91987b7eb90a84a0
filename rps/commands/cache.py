"""`rps cache info|clear`: where the caches are and how big; empty them."""
from __future__ import annotations

import argparse
import json

from ..args import cache_dir, cache_option
from .registry import Command


def add_arguments(k: argparse.ArgumentParser) -> None:
    k.add_argument("action", choices=("info", "clear"),
                   help="info: directory, entries and size; clear: delete every entry")
    cache_option(k)
    k.add_argument("--json", action="store_true", help="print one JSON object (info)")


def run(args: argparse.Namespace) -> int:
    from common.locations import cache_root
    from runtime.cache import cache_info, clear

    if args.action == "clear":
        directory = cache_dir(args, stores=False)  # clearing a full disk frees it
        removed = clear(directory)
        print(f"cleared {directory}: {removed['entries']} entries, "
              f"{removed['bytes'] / 1e6:.1f} MB")
        return 0
    info = cache_info(args.cache if args.cache is not None else cache_root())  # read only
    if args.json:
        from ..answers import CACHE_ANSWER
        print(json.dumps(CACHE_ANSWER.checked(CACHE_ANSWER.payload(info))))
        return 0
    print(f"cache: {info['directory']}" + ("" if info["exists"] else " (empty, not created)"))
    for kind, part in info["kinds"].items():
        print(f"  {kind:<10} {part['entries']:>6} entries  {part['bytes'] / 1e6:9.1f} MB")
    print(f"  {'total':<10} {info['entries']:>6} entries  {info['bytes'] / 1e6:9.1f} MB")
    return 0


COMMAND = Command("cache", "where the caches are and how big; clear them", add_arguments, run)
