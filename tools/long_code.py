#!/usr/bin/env python3
"""Lists the Rust files over 800 lines and the functions over 100 lines (issue 27's goal: none,
tables and generated code excepted), longest first, with the counts on the last line.

Usage: python3 tools/long_code.py [--files N] [--fns N] [PATH ...]   (files or folders;
default: crates python/src)

A function is counted from its `fn` line to the line of its closing brace (doc comments and
attributes not included), found by counting braces outside strings, chars and comments. Files
named *_table.rs and scene/teapot.rs (data) are left out.
"""
import argparse
import os
import re

EXCEPT = re.compile(r"(_table\.rs|scene/teapot\.rs)$")
FN = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?"
                r"(?:extern\s+\"[^\"]*\"\s+)?fn\s+(\w+)")
# Strings (plain and raw), chars, comments: replaced by blanks before braces are counted.
TOKENS = re.compile(r'r(#*)"(?:.|\n)*?"\1|"(?:\\(?:.|\n)|[^"\\])*"|\'(?:\\.|[^\'\\])\'|//[^\n]*|/\*(?:.|\n)*?\*/')


def blank(text):
    """The text with every string, char and comment replaced by spaces (newlines kept)."""
    return TOKENS.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def functions(path):
    """(name, first line, line count) of every function in a file."""
    lines = blank(open(path, encoding="utf-8").read()).split("\n")
    out = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        depth, opened = 0, False
        for j in range(i, len(lines)):
            for c in lines[j]:
                if c == "{":
                    depth, opened = depth + 1, True
                elif c == "}":
                    depth -= 1
                elif c == ";" and not opened and depth == 0:
                    break  # a declaration without a body (trait method, extern)
            else:
                if opened and depth == 0:
                    out.append((m.group(1), i + 1, j - i + 1))
                    break
                continue
            break
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--files", type=int, default=800, help="file length limit (lines)")
    ap.add_argument("--fns", type=int, default=100, help="function length limit (lines)")
    ap.add_argument("paths", nargs="*", default=["crates", "python/src"])
    a = ap.parse_args()
    files = []
    for root in a.paths:
        if os.path.isfile(root):
            files.append(root)
        for d, _, names in os.walk(root):
            files += [os.path.join(d, n) for n in names if n.endswith(".rs")]
    files = sorted(f for f in files if not EXCEPT.search(f))
    long_files = []
    long_fns = []
    for f in files:
        n = sum(1 for _ in open(f, encoding="utf-8"))
        if n >= a.files:
            long_files.append((n, f))
        long_fns += [(k, f"{f}:{line} {name}") for name, line, k in functions(f) if k >= a.fns]
    for n, f in sorted(long_files, reverse=True):
        print(f"file {n:5d} {f}")
    for k, where in sorted(long_fns, reverse=True):
        print(f"fn   {k:5d} {where}")
    print(f"{len(long_files)} files of {a.files}+ lines, {len(long_fns)} functions of {a.fns}+ lines")


if __name__ == "__main__":
    main()
