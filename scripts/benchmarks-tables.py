#!/usr/bin/env python3
"""Copies BENCHMARKS.md's generated tables from the published pages they summarise, so no table is written by hand.

scripts/benchmarks-tables.py [--check] [--file BENCHMARKS.md]

A generated block in BENCHMARKS.md is

    <!-- generated from reports/PAGE.md, "HEADING" -->
    ...
    <!-- end generated -->

and holds the first Markdown table under the heading HEADING of the published page ("SECTION >
HEADING" for a heading the page repeats in each of its sections) (every line
from the first line starting with "|" to the last of that run), with the page's relative links
made relative to the repository root, and a line naming the commits the page's records came
from. The page computed the table from its records (tippe report), so BENCHMARKS.md and the
published pages give one answer. Without --check the blocks are rewritten in place (atomically);
with --check nothing is written and the exit status is 1 when a block differs from its page
(a table edited by hand, or a page republished without running this script). Exit 2 on bad input:
a marker that names no published page or no heading.
"""
import argparse
import glob
import json
import os
import re
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEGIN = re.compile(r'^<!-- generated from (reports/[A-Za-z0-9_.-]+(?:/[A-Za-z0-9_.-]+)*\.md), "([^"]+)" -->$')
END = "<!-- end generated -->"
LINK = re.compile(r"\]\(([^)#:\s][^):\s]*)\)")
COMMIT = re.compile(r"^[0-9a-f]{7,40}$")


class BadInput(Exception):
    pass


def page_table(page, heading, where):
    if ".." in page.split("/"):
        raise BadInput(f'{where}: "{page}": a published page is named without ".."')
    path = os.path.join(ROOT, page)
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
    except OSError as e:
        raise BadInput(f"{where}: {page}: {e.strerror}")
    # "A > B": the heading B within the section of heading A (a page repeats B under each scene).
    start = 0
    for part in [p.strip() for p in heading.split(" > ")]:
        level = None
        if start:
            level = len(lines[start - 1]) - len(lines[start - 1].lstrip("#"))
        found = []
        for i in range(start, len(lines)):
            m = re.match(r"^(#+) (.*)$", lines[i])
            if not m:
                continue
            if level is not None and len(m.group(1)) <= level:
                break  # the end of the enclosing section
            if m.group(2).strip() == part:
                found.append(i)
        if not found:
            raise BadInput(f'{where}: {page} has no heading "{part}"' + ("" if part == heading else f' (in "{heading}")'))
        if len(found) > 1:
            raise BadInput(f'{where}: {page} has {len(found)} headings "{part}": name one that is unique '
                           f'(or its section first: "SECTION > {part}")')
        start = found[0] + 1
    start -= 1
    table = []
    for l in lines[start + 1:]:
        if l.startswith("|"):
            table.append(l)
        elif table or re.match(r"^#+ ", l):
            break
    if not table:
        raise BadInput(f'{where}: {page}: no table under "{heading}"')
    base = os.path.dirname(page)
    # Links on the page are relative to its directory; here they are relative to the root.
    return [LINK.sub(lambda m: "](" + os.path.normpath(os.path.join(base, m.group(1))) + ")", l) for l in table]


def page_commits(page):
    """The commits the records behind a page name (its directory's records; the index's: every comparison's)."""
    d = os.path.dirname(os.path.join(ROOT, page))
    files = glob.glob(os.path.join(d, "*.json")) + glob.glob(os.path.join(d, "*.jsonl"))
    if os.path.normpath(d) == os.path.join(ROOT, "reports"):
        files += glob.glob(os.path.join(d, "*", "comparison.json"))
    commits = set()
    for name in files:
        with open(name, encoding="utf-8") as f:
            for line in f if name.endswith(".jsonl") else [f.read()]:
                line = line.strip()
                if not line:
                    continue
                try:
                    commits.update(found_commits(json.loads(line)))
                except json.JSONDecodeError as e:
                    raise BadInput(f"{os.path.relpath(name, ROOT)}: not JSON: {e}")
    return sorted(c[:12] for c in commits if COMMIT.match(c))


def found_commits(j):
    if isinstance(j, dict):
        for k, v in j.items():
            if k == "git_commit" and isinstance(v, str):
                yield v
            else:
                yield from found_commits(v)
    elif isinstance(j, list):
        for v in j:
            yield from found_commits(v)


def render(text, name):
    lines = text.split("\n")
    out, i = [], 0
    blocks = 0
    while i < len(lines):
        m = BEGIN.match(lines[i])
        if lines[i].startswith("<!-- generated from") and not m:
            raise BadInput(f'{name}:{i + 1}: a marker is <!-- generated from reports/PAGE.md, "HEADING" -->')
        out.append(lines[i])
        i += 1
        if not m:
            continue
        # The block ends at the first END; another marker before it means this one lost its end
        # (taking the next block's would swallow that block).
        end = next((j for j in range(i, len(lines)) if lines[j] == END or lines[j].startswith("<!-- generated from")), None)
        if end is None:
            raise BadInput(f"{name}:{i}: no {END} after this marker")
        if lines[end] != END:
            raise BadInput(f"{name}:{i}: no {END} after this marker before the next one (line {end + 1})")
        page, heading = m.group(1), m.group(2)
        commits = page_commits(page)
        out.append("")
        out.extend(page_table(page, heading, f"{name}:{i}"))
        out.append("")
        out.append(f"Copied from [{page}]({page}) (\"{heading}\") by `scripts/benchmarks-tables.py`; "
                   f"the records were made at commit{'s' if len(commits) != 1 else ''} {', '.join(commits) or 'none named'}.")
        out.append("")
        out.append(END)
        i = end + 1
        blocks += 1
    return "\n".join(out), blocks


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when a block differs from its page; write nothing")
    ap.add_argument("--file", default=os.path.join(ROOT, "BENCHMARKS.md"))
    a = ap.parse_args()
    name = os.path.relpath(a.file, ROOT)
    try:
        with open(a.file, encoding="utf-8") as f:
            text = f.read()
        new, blocks = render(text, name)
    except (BadInput, OSError) as e:
        print(f"benchmarks-tables: {e}", file=sys.stderr)
        return 2
    if a.check:
        if new != text:
            old_lines, new_lines = text.split("\n"), new.split("\n")
            first = next((k for k, (x, y) in enumerate(zip(old_lines, new_lines)) if x != y), min(len(old_lines), len(new_lines)))
            print(f"benchmarks-tables: {name}:{first + 1}: a generated table differs from its published page "
                  f"(run scripts/benchmarks-tables.py); here: {old_lines[first] if first < len(old_lines) else '(end)'!r}; "
                  f"the page gives: {new_lines[first] if first < len(new_lines) else '(end)'!r}", file=sys.stderr)
            return 1
        print(f"benchmarks-tables: {name}: {blocks} generated table(s) match their pages")
        return 0
    if new != text:
        try:
            fd, tmp = tempfile.mkstemp(dir=os.path.dirname(a.file), prefix=".benchmarks-tables.")
        except OSError as e:
            print(f"benchmarks-tables: {name}: {e}", file=sys.stderr)
            return 2
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(new)
            os.chmod(tmp, os.stat(a.file).st_mode & 0o777)
            os.replace(tmp, a.file)
        except BaseException as e:
            # Nothing half-written: the file stays as it was and the temporary goes.
            os.unlink(tmp)
            if not isinstance(e, OSError):
                raise
            print(f"benchmarks-tables: {name}: {e}", file=sys.stderr)
            return 2
    print(f"benchmarks-tables: {name}: {blocks} generated table(s) written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
