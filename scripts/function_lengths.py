#!/usr/bin/env python3
"""Functions longer than a reader takes in at once (issue 21: 80 lines).

Counts each function defined at namespace scope in the given .cc and .h
files (or folders, searched recursively), in lines that hold code: blank
lines and comment-only lines do not count, as in the issue's figures.
A folder that is not there is skipped with a note, so one list of folders
serves trees with and without an optional one (lab/); none there is an error.

  scripts/function_lengths.py [--limit 80] PATH...
Prints one line per function over the limit and exits 1 if there is any.
Runs on any Python 3 (the standard library only).
"""
import argparse
import pathlib
import re
import sys


def code_lines(text):
    """The text with comments and string contents blanked, line by line."""
    out, i, n = [], 0, len(text)
    state = None  # None, "line", "block", '"', "'"
    buf = []
    while i < n:
        c, nxt = text[i], text[i + 1] if i + 1 < n else ""
        if state is None:
            if c == "/" and nxt == "/":
                state = "line"; i += 2; continue
            if c == "/" and nxt == "*":
                state = "block"; i += 2; continue
            if c == 'R' and nxt == '"':  # raw string: R"delim( ... )delim"
                end = text.index("(", i)
                close = ")" + text[i + 2:end] + '"'
                stop = text.index(close, end) + len(close)
                buf.append('""' + "\n" * text.count("\n", i, stop)); i = stop; continue
            if c in "\"'":
                state = c; buf.append(c); i += 1; continue
            buf.append(c)
        elif state == "line":
            if c == "\n":
                state = None; buf.append(c)
        elif state == "block":
            if c == "*" and nxt == "/":
                state = None; i += 2; continue
            if c == "\n":
                buf.append(c)
        else:  # inside a string or character literal
            if c == "\\":
                i += 2; continue
            if c == state:
                state = None; buf.append(c)
        i += 1
    return "".join(buf).split("\n")


def long_functions(path, limit):
    lines = code_lines(path.read_text())
    depth, namespaces, start, found = 0, 0, None, []
    for number, line in enumerate(lines, 1):
        stripped = line.strip()
        if depth == namespaces and re.match(r"^(inline\s+)?namespace\b[^;]*\{", stripped):
            namespaces += 1; depth += 1; continue
        opens, closes = line.count("{"), line.count("}")
        if depth == namespaces and opens > closes and start is None and ")" in "".join(lines[max(0, number - 6):number]):
            if not re.match(r"^(struct|class|enum|union)\b", stripped) and "=" not in stripped.split("(")[0]:
                start = number
                while start > 1 and lines[start - 2].strip() and lines[start - 2].strip()[-1] not in ";{}":
                    start -= 1  # the signature's first line
        depth += opens - closes
        if depth < namespaces:  # a namespace closed
            namespaces = depth
        if start is not None and depth == namespaces:
            body = [l for l in lines[start - 1:number] if l.strip()]
            if len(body) > limit:
                found.append((start, len(body), lines[start - 1].strip()[:80]))
            start = None
    return found


def source_files(paths):
    """The .cc and .h files of the paths (files, or folders searched
    recursively), or None when no path is there. Missing ones are noted."""
    files, present = [], 0
    for p in paths:
        if not p.exists():
            print(f"note: {p} is not there; skipped", file=sys.stderr)
            continue
        present += 1
        files += sorted(f for f in p.rglob("*") if f.suffix in (".cc", ".h")) if p.is_dir() else [p]
    return files if present else None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--limit", type=int, default=80)
    parser.add_argument("paths", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    files = source_files(args.paths)
    if files is None:
        parser.error("none of the paths is there")
    over = [(f, *hit) for f in files for hit in long_functions(f, args.limit)]
    for f, line, count, head in over:
        print(f"{f}:{line}: {count} lines over {args.limit}: {head}")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
