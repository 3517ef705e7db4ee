#!/usr/bin/env python3
"""Lists the C++ functions (and lambdas at namespace or class scope) of the given files
or folders with their length in lines, longest first; exits 1 when one is longer than
--limit. A function is a brace block whose opening line has a ')' before the '{' and
does not start with a control keyword; strings, characters and comments are skipped."""
import argparse
import os
import re
import sys

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try)\b")
SOURCES = (".cpp", ".hpp", ".h", ".cc")


def strip(text):
    """Replaces comments and string/char literals by spaces, keeping line breaks."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j, n - 1) - i + 1))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    text = strip(open(path, encoding="utf-8", errors="replace").read())
    lines = text.split("\n")
    stack = []  # (kind, start line, header)
    found = []
    for no, line in enumerate(lines, 1):
        for pos, c in enumerate(line):
            if c == "{":
                head = line[:pos]
                # The header may start on earlier lines (wrapped parameters).
                k = no - 2
                while k >= 0 and ")" in head and "(" not in head and no - k < 8:
                    head = lines[k] + " " + head
                    k -= 1
                inside = any(kind == "function" for kind, _, _ in stack)
                is_function = (not inside and ")" in head and not CONTROL.match(head)
                               and not re.search(r"\b(namespace|struct|class|enum)\b[^()]*$", head))
                stack.append(("function" if is_function else "block", no, head.strip()))
            elif c == "}" and stack:
                kind, start, head = stack.pop()
                if kind == "function":
                    name = re.findall(r"([~\w:<>]+)\s*\(", head)
                    found.append((no - start + 1, path, start, name[0] if name else head[:40]))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--limit", type=int, default=0, help="fail above this many lines")
    parser.add_argument("--top", type=int, default=15)
    parser.add_argument("--over", type=int, default=0, help="list every function over N lines")
    args = parser.parse_args()
    files = []
    for p in args.paths:
        if os.path.isdir(p):
            for root, _, names in os.walk(p):
                files += [os.path.join(root, f) for f in sorted(names) if f.endswith(SOURCES)]
        else:
            files.append(p)
    found = sorted((f for path in files for f in functions(path)), reverse=True)
    shown = [f for f in found if f[0] > args.over] if args.over else found[: args.top]
    for length, path, start, name in shown:
        print(f"{length:5d}  {path}:{start}  {name}")
    if args.limit and found and found[0][0] > args.limit:
        print(f"function_lengths: {found[0][3]} ({found[0][1]}:{found[0][2]}) has {found[0][0]} "
              f"lines, over the limit of {args.limit}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
