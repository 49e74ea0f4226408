#!/usr/bin/env bash
# Regenerates the published comparison reports in reports/ from every harness/scenes/*.toml: scripts/publish-reports.sh [BUILD_DIR] (default build).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
tippe="$build/tippe"
if [ ! -x "$tippe" ]; then
  echo "publish-reports: $tippe not found; build it first: cmake --build $build --target tippe" >&2
  exit 2
fi
# One run per core by default; JOBS=N overrides (each scene runs the reference and three engines).
jobs="${JOBS:-$(nproc 2>/dev/null || echo 2)}"
# REPORTS_DIR=DIR writes elsewhere (e.g. to try the script without touching reports/).
reports="${REPORTS_DIR:-$root/reports}"
# Trajectories and plot data stay in a scratch directory: the published pages need only the
# records, the SVGs and the pages themselves.
work="$(mktemp -d "${TMPDIR:-/tmp}/tippe-publish.XXXXXX")"
trap 'rm -rf "$work"' EXIT

html_escape() { sed -e 's/&/\&amp;/g' -e 's/</\&lt;/g' -e 's/>/\&gt;/g' -e 's/"/\&quot;/g'; }
# The scene's name key (what tippe calls the scene), else the file stem.
scene_name() {
  local n
  n="$(sed -n 's/^name[[:space:]]*=[[:space:]]*"\([^"]*\)".*/\1/p' "$1" | head -n 1)"
  [ -n "$n" ] && echo "$n" || basename "$1" .toml
}
scene_description() { sed -n 's/^description[[:space:]]*=[[:space:]]*"\(.*\)"[[:space:]]*$/\1/p' "$1" | head -n 1; }

# Scene paths relative to the repository root, so the records name them the same everywhere.
cd "$root"
mkdir -p "$reports"
rows=""
for scene in harness/scenes/*.toml; do
  name="$(scene_name "$scene")"
  echo "publish-reports: $scene -> reports/$name/" >&2
  # A fresh reference (no cache): what is published comes from this build alone.
  "$tippe" compare "$scene" --out "$work/$name" --jobs "$jobs" --no-cache
  rm -rf "${reports:?}/$name"
  mkdir -p "$reports/$name"
  cp "$work/$name/comparison.json" "$reports/$name/"
  for svg in "$work/$name"/*.svg; do
    [ -e "$svg" ] && cp "$svg" "$reports/$name/"
  done
  # The pages from the published files alone: they link only what is published (no trajectory
  # CSVs) and show the plots made from the trajectories in the scratch directory.
  "$tippe" report "$reports/$name" >/dev/null
  summary="$("$tippe" report "$work/$name" --summary-line)"
  rows+="<tr><th><a href=\"$name/index.html\">$(printf '%s' "$name" | html_escape)</a></th>"
  rows+="<td>$(scene_description "$scene" | html_escape)</td><td>$(printf '%s' "$summary" | html_escape)</td></tr>"$'\n'
done

# The finding the index opens with: one sentence per engine over every scene's comparison.json.
verdicts="$("$tippe" report "$reports" --index-verdict)"
verdict_html=""
while IFS= read -r line; do
  [ -n "$line" ] && verdict_html+="<p class=\"verdict\">$(printf '%s' "$line" | html_escape)</p>"$'\n'
done <<<"$verdicts"

commit="$(git -C "$root" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)"
if [ -n "$(git -C "$root" status --porcelain 2>/dev/null | head -n 1)" ]; then commit="$commit (working tree with changes)"; fi
date="$(date -u +%Y-%m-%dT%H:%M:%SZ)"

cat >"$reports/index.html.tmp" <<EOF
<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>tippe: engine comparison reports</title>
<style>
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 1100px; padding: 0 1em; color: #222; }
table { border-collapse: collapse; } th, td { border: 1px solid #ccc; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
thead th { background: #f0f0f0; }
footer { margin-top: 2em; font-size: 0.85em; color: #555; }
.verdict { background: #eef4fb; border-left: 4px solid #0072b2; padding: 0.4em 0.8em; margin: 0.3em 0; }
</style>
</head>
<body>
<h1>Tippe top: engines against the analytic reference</h1>
${verdict_html}<p>One page per scene: the Bullet, ODE, MuJoCo and DART engines run on the same scene as the analytic
reference model and are compared sample by sample. How to read a page: README.md in this directory.</p>
<table>
<thead><tr><th>scene</th><th>description</th><th>inversion (reference and engines)</th></tr></thead>
<tbody>
${rows}</tbody>
</table>
<h2>Sweeps</h2>
<p>Published by their own commands (see README.md): each page is made from its records.jsonl alone.</p>
<ul>
<li><a href="sweep-default/index.html">sweep-default</a>: work-precision of every engine over its time step, and of the reference over its tolerance (scripts/publish-sweep.sh)</li>
<li><a href="sweep-extremes/index.html">sweep-extremes</a>: the extremes battery, with its stability map (scripts/publish-extremes.sh)</li>
<li><a href="sweep-extremes-long/index.html">sweep-extremes-long</a>: 1e4 spin periods without friction (scripts/publish-extremes.sh)</li>
<li><a href="sweep-modelling/index.html">sweep-modelling</a>: the engines' modelling choices over the time step, and which of them move the verdict (SWEEP=harness/sweeps/modelling.toml scripts/publish-sweep.sh)</li>
<li><a href="sweep-horizon/index.html">sweep-horizon</a>: the Coulomb tops to 30 s, and whether each engine's departure from the rolling regime goes away as the step shrinks (SWEEP=harness/sweeps/horizon.toml scripts/publish-sweep.sh)</li>
<li><a href="sweep-boundaries/index.html">sweep-boundaries</a>: the largest safe time step of every engine on every scene, by boundary search (SWEEP=harness/sweeps/boundaries.toml scripts/publish-sweep.sh)</li>
</ul>
<footer>Generated by scripts/publish-reports.sh on ${date} from commit $(printf '%s' "$commit" | html_escape).</footer>
</body>
</html>
EOF
mv "$reports/index.html.tmp" "$reports/index.html"

{
printf '# Published comparison reports\n\n'
printf 'The verdict over every scene (one sentence per engine, from the comparison.json files):\n\n'
printf '%s\n' "$verdicts" | sed 's/^/- /'
printf '\n'
cat <<'EOF'
`index.html` lists every shipped scene (`harness/scenes/*.toml`); each `SCENE/` directory holds
one comparison of the Bullet, ODE, MuJoCo and DART engines against the analytic reference model:

- `index.html`: the page (tables, findings, plots, every engine's settings and notes, provenance).
- `report.md`: the same summary as text, for terminals and CI logs.
- `comparison.json`: the records everything else is made from: the scene, the reference's and each
  engine's run summary (status, events, work, settings, notes) and the metrics.
- `*.svg`: the plots.

The trajectories (`reference.csv`, `ENGINE.csv`, one row per sample) are not kept here, to keep the
repository small. To get them, run the comparison yourself (see below) or
`tippe compare harness/scenes/SCENE.toml --out DIR`.

## Regenerating

From the repository root, with the `tippe` target built in `build/`:

    cmake --build build --target tippe
    scripts/publish-reports.sh build

`JOBS=N` sets how many runs go in parallel (default: one per core). The script runs
`tippe compare SCENE.toml --out TMP --no-cache` for every scene (a fresh reference, not the cache),
copies the pages, records and plots into `reports/SCENE/`, and rewrites this file and `index.html`.
One page can also be rebuilt from its records alone with `tippe report DIR` (plots need the CSVs;
without them the SVGs already there are kept).

## Sweeps and the extremes battery

`sweep-default/` (`scripts/publish-sweep.sh build`), `sweep-modelling/`, `sweep-horizon/` and
`sweep-boundaries/` (`SWEEP=harness/sweeps/NAME.toml scripts/publish-sweep.sh build`), `sweep-extremes/` and
`sweep-extremes-long/` (`scripts/publish-extremes.sh build`) are sweep reports: `index.html` and `report.md` are made from
`records.jsonl` alone (one line per run: settings, status, class, errors against the reference,
CPU time, steps), `sweep.json` is the sweep file they ran. A sweep report opens with one sentence
per engine: at how many of its points it is in the reference's regime (per scene), its inversion-time
error where both invert, and the setting to use on each scene (the cheapest point below 1 %
inversion-time error, else below 10 %, where the reference inverts; the cheapest finished point in
the reference's regime where it does not). It then has, per scene, the
work-precision charts (error against CPU seconds, log-log, one line per setup), the cheapest setting
of each engine below 10 %, 1 % and 0.1 % inversion-time error (never a point the stability map
classes unphysical or diverged), the empirical order of convergence,
the regime table, and every point with its class. Its stability map gives, per setup, scenes down and the ladder
across, the class of every run: `ok` (green), `ok, regime differs` (yellow: it inverts where the
reference does not, or the reverse), `unphysical` (orange: energy gain in a dissipative scene, or
Jellett's integral drifting by more than 1e-3 where it must hold), `clamped` (purple: an engine limit
hit), `diverged` (red: NaN, energy above 2 E0, G below the floor by more than R/10, speed blow-up),
`failed` (grey), each with the time it happened. "The reference on each scene" lists the reference's
own run: method, tolerance, cost, energy balance and Jellett drift. A sweep with a grid (a second axis, e.g. an
engine's body frame over its time step) draws one line per grid value, and its "Modelling choices"
section says, per engine and scene, whether a choice's values give different regimes or inversion
times more than 1 % apart at the same time step, and by how much.

## Reading a page

Every engine is sampled on the scene's grid (`run.sample_interval`, from t = 0); metrics compare
the engine with the reference sample by sample, up to the end of the shorter run ("compared to t").
Time is in the scene's units (seconds for SI scenes, dimensionless for the source's scaled top).

| column | meaning |
|---|---|
| status | `ok`, or how and when the run ended early (`diverged`, `contact_lost`, `unphysical`, `clamped`, `failed`) |
| inversion t | first time the tilt theta crosses 90 degrees; `-` when it never does |
| inversion error | engine minus reference time, and that relative to the reference's time; `missing`: the reference inverts and the engine does not; `extra`: the reverse |
| stem contact t, error | the same for the first touchdown of the stem |
| tilt RMS (rad) | root mean square of theta_engine - theta_reference over the common samples (max in "More metrics") |
| energy max error (/E0) | largest abs(E_engine - E_reference) divided by the reference's initial energy E0 |
| contact path RMS (/R) | RMS distance between the engine's and the reference's floor contact points (x_C, y_C), divided by the ball radius R |
| Jellett drift | largest relative change of Jellett's integral J = L_G . R_C within a stretch of contact on one surface (J is conserved only there) |
| steps, CPU s | integrator or engine steps and CPU seconds of the run |
| cost ratio | engine CPU seconds / reference CPU seconds |

"More metrics" adds: the maximum tilt error; E_final/E0 of the engine; energy gain events (in a
scene whose contact law dissipates, the number of samples where E rose by more than 1e-6 E0 over
the previous one: energy the integrator injected) and the largest such rise; path maxima; the path
of the centre of mass G (/R); the RMS error of the contact latitude on the ball; Jellett drift on
the ball and on the stem separately; the number of contact-surface switches the engine reported
(many: it chatters between ball and stem); wall seconds and the real-time factor (simulated / wall
time). comparison.json lists the first 100 "switch" events of a run and counts the rest in
"events_omitted".

Colours: an event error is green below 1 %, amber below 10 %, red above, and red when only one side
has the event; a status other than ok is red. Other metrics are coloured only when the comparison
carries tolerances. Findings list, in words, events one side lacks, energy gain events and runs that
ended early.

Every page opens with its verdict: one sentence per engine saying whether it is in the reference's
regime (inverts when the reference does, and not otherwise) and by how much its inversion time
differs, taken from comparison.json alone. Links at the top lead back to this index and to the data
files (comparison.json; the trajectories when the directory has them).

Plots: tilt theta(t) of every engine over the reference (thick black; dashed line at the
reference's inversion) and |theta - theta_ref| on a log axis, E(t)/E0 and |E - E_ref|/E0 on a log
axis (the reference interpolated linearly to each engine's sample times), the floor contact path
(x_C, y_C)/R (the line breaks where the contact switches between the ball and the stem), J(t)/J0
and F_n(t)/(M g). Every axis carries its unit: seconds for SI scenes, units of sqrt(R/g) for the
source's dimensionless top. Engines keep one colour from the Okabe-Ito palette (colour-blind safe)
and one marker on every page. Long series are decimated to about 2000 points, keeping each stretch's
extremes. `tippe report DIR` remakes the plots from the trajectories; without them (as here) it
keeps the SVGs that are there.

The footer of each page gives what the numbers depend on: compiler and flags, engine versions, git
commit, machine, date and the scene file's content hash.
EOF
} >"$reports/README.md.tmp"
mv "$reports/README.md.tmp" "$reports/README.md"
echo "publish-reports: wrote $reports/index.html" >&2
