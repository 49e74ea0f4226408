#!/usr/bin/env python3
"""Compares freshly made records with the published ones: exit 0 when they agree, 1 on drift, 2 on bad input.

check_published.py comparison PUBLISHED/comparison.json NEW/comparison.json
check_published.py sweep PUBLISHED/records.jsonl NEW/records.jsonl

What must agree (the verdicts the published pages state): for the reference and every engine of
a comparison, the run's status, whether it inverts (its regime), and the times of its inversion,
first stem contact, end of run, status and of every listed event (to 1e-6, relative to the time
where it exceeds 1, else absolute); for every point of the new sweep (matched to the published
one by point id), its status, class, regime against the reference, and the same times. Costs,
errors and dates are not compared: they change with the machine.
"""
import json
import sys

TOL = 1e-6


def close(a, b):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= TOL * max(1.0, abs(a), abs(b))


def compare_times(where, old, new, keys, problems):
    for k in keys:
        a, b = old.get(k), new.get(k)
        if isinstance(a, (int, float)) or isinstance(b, (int, float)) or a is None or b is None:
            if not close(a, b):
                problems.append(f"{where}: {k} published {a}, now {b}")


def compare_run(where, old, new, problems):
    if old.get("status") != new.get("status"):
        problems.append(f"{where}: status published {old.get('status')!r}, now {new.get('status')!r}")
    if (old.get("inversion_time") is None) != (new.get("inversion_time") is None):
        said = lambda s: "inverts" if s.get("inversion_time") is not None else "does not invert"
        problems.append(f"{where}: regime published {said(old)}, now {said(new)}")
    compare_times(where, old, new, ["inversion_time", "stem_contact_time", "final_time", "status_time"], problems)
    ev_old, ev_new = old.get("events", []), new.get("events", [])
    if len(ev_old) != len(ev_new) or old.get("events_omitted") != new.get("events_omitted"):
        problems.append(f"{where}: {len(ev_old)} events published (+{old.get('events_omitted') or 0} omitted), "
                        f"now {len(ev_new)} (+{new.get('events_omitted') or 0})")
    for i, (a, b) in enumerate(zip(ev_old, ev_new)):
        if a.get("name") != b.get("name") or not close(a.get("time"), b.get("time")):
            problems.append(f"{where}: event {i} published {a.get('name')} at {a.get('time')}, now {b.get('name')} at {b.get('time')}")


def check_comparison(old_file, new_file):
    old, new = load_json(old_file), load_json(new_file)
    problems = []
    scene = old.get("scene_name", old_file)
    compare_run(f"{scene}: reference", old["reference"]["summary"], new["reference"]["summary"], problems)
    engines_old = {e["engine"]: e for e in old["engines"]}
    engines_new = {e["engine"]: e for e in new["engines"]}
    if sorted(engines_old) != sorted(engines_new):
        problems.append(f"{scene}: engines published {sorted(engines_old)}, now {sorted(engines_new)}")
    for name in sorted(set(engines_old) & set(engines_new)):
        compare_run(f"{scene}: {name}", engines_old[name]["summary"], engines_new[name]["summary"], problems)
        a = engines_old[name]["metrics"].get("inversion_event")
        b = engines_new[name]["metrics"].get("inversion_event")
        if a != b:
            problems.append(f"{scene}: {name}: inversion event published {a}, now {b}")
    return problems


def check_sweep(old_file, new_file):
    old = {r["point_id"]: r for r in load_jsonl(old_file)}
    new = load_jsonl(new_file)
    if not new:
        return [f"{new_file}: no records"]
    problems = []
    for r in new:
        where = f"{r.get('scene')} {r.get('setup')} {r.get('ladder_key')}={r.get('ladder_label')}"
        p = old.get(r["point_id"])
        if p is None:
            problems.append(f"{where}: point {r['point_id']} is not among the published records "
                            f"(the check's sweep no longer matches the published sweep file)")
            continue
        if p["class"]["name"] != r["class"]["name"]:
            problems.append(f"{where}: class published {p['class']['name']!r}, now {r['class']['name']!r}")
        if p["reference"]["class"] != r["reference"]["class"]:
            problems.append(f"{where}: the reference's class published {p['reference']['class']!r}, now {r['reference']['class']!r}")
        a, b = p["metrics"].get("inversion_event"), r["metrics"].get("inversion_event")
        if a != b:
            problems.append(f"{where}: regime (inversion event) published {a}, now {b}")
        compare_run(where, p, r, problems)
        compare_times(where, p, r, ["reference_inversion_time", "reference_stem_contact_time"], problems)
        if not close(p["class"].get("time"), r["class"].get("time")):
            problems.append(f"{where}: class time published {p['class'].get('time')}, now {r['class'].get('time')}")
    return problems


def load_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        print(f"{path}: cannot read: {e}", file=sys.stderr)
        sys.exit(2)


def load_jsonl(path):
    try:
        with open(path, encoding="utf-8") as f:
            return [json.loads(line) for line in f if line.strip()]
    except (OSError, ValueError) as e:
        print(f"{path}: cannot read: {e}", file=sys.stderr)
        sys.exit(2)


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("comparison", "sweep"):
        print(__doc__.strip().split("\n\n")[0] + "\nusage: check_published.py comparison|sweep PUBLISHED NEW", file=sys.stderr)
        return 2
    kind, old_file, new_file = sys.argv[1:]
    problems = (check_comparison if kind == "comparison" else check_sweep)(old_file, new_file)
    for p in problems:
        print(f"drift: {p}")
    print(f"check_published: {new_file} against {old_file}: " + (f"{len(problems)} differences" if problems else "as published"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
