"""What the study scripts share: the machine and its load, for the line that says where a
page's figures come from, and the generated blocks of a page.

A page that mixes prose with figures marks each generated part

    <!-- generated: NAME -->
    ...
    <!-- end generated: NAME -->

and its script replaces what lies between the two lines (`fill`); a block missing from the
page is an error, so that a renamed section cannot silently stop being regenerated.

As a program (for the shell scripts):
    study_page.py load                 prints the 1, 5 and 15 min load averages
    study_page.py machine              prints e.g. "AMD EPYC, 2 cores, Linux x86_64"
    study_page.py fill PAGE NAME       the block NAME of PAGE becomes the standard input
"""
import os
import platform
import re
import sys


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def machine():
    """The CPU model, the cores and the system, as a page names them."""
    return "%s, %d cores, %s %s" % (cpu_name(), os.cpu_count() or 0, platform.system(),
                                    platform.machine())


def load():
    """The 1, 5 and 15 min load averages, as /proc/loadavg gives them."""
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def load_span(before, after):
    """'load average (1, 5, 15 min) 0.52 0.40 0.31 before, 2.10 1.20 0.60 after'."""
    return "load average (1, 5, 15 min) %s before the run, %s after" % (before, after)


def fill(path, blocks):
    """Replaces the generated blocks of the page at path: blocks maps NAME to its text."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    for name, body in blocks.items():
        pattern = re.compile(r"(<!-- generated: %s -->\n).*?(<!-- end generated: %s -->)"
                             % (re.escape(name), re.escape(name)), re.DOTALL)
        if not pattern.search(text):
            sys.exit("%s: no generated block %s" % (path, name))
        text = pattern.sub(lambda m: m.group(1) + body.rstrip("\n") + "\n" + m.group(2), text)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def table(header, rows):
    """A markdown table."""
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def g3(x):
    """Three significant digits, as the pages print measured figures."""
    if x != x:
        return "n/a"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return "%.2e" % x
    return "%.3g" % x


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else ""
    if what == "load":
        print(load())
    elif what == "machine":
        print(machine())
    elif what == "fill" and len(sys.argv) == 4:
        fill(sys.argv[2], {sys.argv[3]: sys.stdin.read()})
    else:
        sys.exit("usage: study_page.py load | machine | fill PAGE NAME")
