#!/usr/bin/env python3
"""Tests scripts/benchmarks-tables.py: BENCHMARKS.md's generated tables match the published pages, a table edited by hand is caught, bad markers are refused."""
import os
import re
import subprocess
import sys
import tempfile

root = sys.argv[1]
script = os.path.join(root, "scripts", "benchmarks-tables.py")
failures = []


def run(*args):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True)


def expect(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + (": " + detail if detail and not ok else ""))
    if not ok:
        failures.append(name)


# 1. The committed BENCHMARKS.md: every generated block equals its page's table.
r = run("--check")
expect("committed tables match their pages", r.returncode == 0, r.stderr.strip())
blocks = int(re.search(r"(\d+) generated table", r.stdout).group(1)) if r.returncode == 0 else 0
expect("BENCHMARKS.md has generated tables", blocks >= 2, f"{blocks} found")

with open(os.path.join(root, "BENCHMARKS.md"), encoding="utf-8") as f:
    text = f.read()
with tempfile.TemporaryDirectory() as d:
    copy = os.path.join(d, "BENCHMARKS.md")

    def check_with(t):
        with open(copy, "w", encoding="utf-8") as f:
            f.write(t)
        return run("--check", "--file", copy)

    # 2. One cell of a generated table edited by hand: --check fails and names the line.
    begin = text.index("<!-- generated from")
    row = text.index("\n|", begin) + 1            # the table's first line
    row = text.index("\n|", text.index("\n|", row) + 1) + 1  # its first data row (past the separator)
    cell_end = text.index("|", row + 1)
    edited = text[:row + 1] + " hand-edited " + text[cell_end:]
    r = check_with(edited)
    line = edited[:row].count("\n") + 1
    expect("a hand-edited cell fails the check", r.returncode == 1 and f":{line}:" in r.stderr, r.stderr.strip())
    # ... and the rewrite restores the page's table.
    r2 = run("--file", copy)
    with open(copy, encoding="utf-8") as f:
        expect("rewriting restores the table", r2.returncode == 0 and f.read() == text)

    # 3. Bad input: exit 2 with the file and the reason, nothing written.
    for name, marker, reason in [
        ("a page outside reports/", '<!-- generated from README.md, "x" -->', "a marker is"),
        ("a missing page", '<!-- generated from reports/nope/report.md, "x" -->', "No such file"),
        ("a heading the page lacks", '<!-- generated from reports/README.md, "No such heading" -->', 'has no heading'),
        ("\"..\" in the page", '<!-- generated from reports/../README.md, "x" -->', 'without ".."'),
        ("a heading the page has twice", '<!-- generated from reports/sweep-default/report.md, "Charts" -->', 'name one that is unique'),
    ]:
        bad = text + "\n" + marker + "\n<!-- end generated -->\n"
        r = check_with(bad)
        expect("refuses " + name, r.returncode == 2 and "BENCHMARKS.md" in r.stderr and reason in r.stderr, r.stderr.strip())
    # A heading the page repeats, named within its section: the table of that section.
    r = check_with(text + '\n<!-- generated from reports/sweep-default/report.md, "Scene toy_viscous > Regime: does it still invert?" -->\n<!-- end generated -->\n')
    expect("a repeated heading within its section", r.returncode == 1, r.stderr.strip())
    run("--file", copy)
    with open(copy, encoding="utf-8") as f:
        got = f.read()
    with open(os.path.join(root, "reports", "sweep-default", "report.md"), encoding="utf-8") as f:
        page = f.read()
    section = page[page.index("## Scene toy_viscous"):]
    section = section[section.index("### Regime: does it still invert?"):]
    first_row = next(l for l in section.split("\n") if l.startswith("| "))
    expect("... copies that section's table", first_row in got and got.count("<!-- generated from") == blocks + 1)
    r = check_with(text + '\n<!-- generated from reports/README.md, "Tippe top: engines against the analytic reference" -->\n')
    expect("refuses a block without its end", r.returncode == 2 and "no <!-- end generated -->" in r.stderr, r.stderr.strip())
    # A marker whose end is missing before the next block: refused, not run to the next block's end.
    lost = text.replace("<!-- end generated -->", "", 1)
    r = check_with(lost)
    expect("refuses a block whose end comes after the next marker",
           r.returncode == 2 and "before the next one" in r.stderr, r.stderr.strip())
    r = run("--file", copy)
    with open(copy, encoding="utf-8") as f:
        expect("... and writes nothing", r.returncode == 2 and f.read() == lost)
    expect("... nor leaves a temporary file", not any(n.startswith(".benchmarks-tables.") for n in os.listdir(d)))

sys.exit(1 if failures else 0)
