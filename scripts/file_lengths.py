#!/usr/bin/env python3
"""Source files longer than one job needs (issue 45: 500 lines).

Counts every line of each .cc and .h file in the given files or folders
(searched recursively; a folder that is not there is skipped with a note, as
function_lengths.py does): the length a reader scrolls through.

  scripts/file_lengths.py [--limit 500] [--allow FILE]... [--exclude GLOB]... PATH...
--allow FILE: a file known to be over the limit and being split; it is
  reported but does not fail the check, and an allowed file that is no longer
  over the limit (or gone) is noted so that it leaves the list.
--exclude GLOB: file names (fnmatch, e.g. '*_test.cc') not counted at all.
Prints one line per file over the limit and exits 1 if any is not allowed.
Runs on any Python 3 (the standard library only).
"""
import argparse
import fnmatch
import pathlib
import sys

from function_lengths import source_files


def line_count(path):
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--limit", type=int, default=500)
    parser.add_argument("--allow", action="append", default=[], type=pathlib.Path)
    parser.add_argument("--exclude", action="append", default=[])
    parser.add_argument("paths", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    files = source_files(args.paths)
    if files is None:
        parser.error("none of the paths is there")
    files = [f for f in files if not any(fnmatch.fnmatch(f.name, g) for g in args.exclude)]
    allowed = {a.resolve() for a in args.allow}
    failed = False
    for f in files:
        lines = line_count(f)
        if lines <= args.limit:
            continue
        known = f.resolve() in allowed
        allowed.discard(f.resolve())
        failed |= not known
        print(f"{f}: {lines} lines over {args.limit}" + (" (allowed: being split)" if known else ""))
    for a in sorted(allowed):
        print(f"note: {a} is allowed but not over {args.limit} lines (or gone): take it off --allow")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
