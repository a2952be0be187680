#!/usr/bin/env python3
"""Source files longer than one job needs (issue 45: 500 lines).

Counts every line of each .cc and .h file in the given files or folders
(searched recursively; a folder that is not there is skipped with a note, as
function_lengths.py does): the length a reader scrolls through.

  scripts/file_lengths.py [--limit 500] PATH...
Prints one line per file over the limit and exits 1 if there is any.
Runs on any Python 3 (the standard library only).
"""
import argparse
import pathlib
import sys

from function_lengths import source_files


def line_count(path):
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--limit", type=int, default=500)
    parser.add_argument("paths", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    files = source_files(args.paths)
    if files is None:
        parser.error("none of the paths is there")
    failed = False
    for f in files:
        lines = line_count(f)
        if lines > args.limit:
            failed = True
            print(f"{f}: {lines} lines over {args.limit}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
