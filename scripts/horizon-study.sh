#!/usr/bin/env bash
# The Coulomb scenes at the engines' default settings to their own horizon and to 30 s, MuJoCo in both body frames: a Markdown table on stdout (docs/findings/verdict-horizon.md): scripts/horizon-study.sh [BUILD_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
tippe="$build/tippe"
[ -x "$tippe" ] || { echo "horizon-study: $tippe not found; build it first" >&2; exit 2; }
work="$(mktemp -d "${TMPDIR:-/tmp}/tippe-horizon.XXXXXX")"
trap 'rm -rf "$work"' EXIT
cd "$root"
# One cell: inversion time / first stem contact ("-" when none), and the count of contact switches.
cell() {
  local out="$1" inv stem switches
  inv="$(sed -n 's/^inversion *//p' "$out/stdout")"
  stem="$(sed -n 's/^stem contact *//p' "$out/stdout")"
  switches="$(grep -o '"name": "switch"' "$out/summary.json" | wc -l)"
  [ "$inv" = none ] && inv="-"
  [ "$stem" = none ] && stem="-"
  printf '%s / %s (%s sw)' "$inv" "$stem" "$switches"
}
echo "| scene | horizon | reference | ODE | Bullet | MuJoCo, frame at G | MuJoCo, frame at O | DART |"
echo "|---|---|---|---|---|---|---|---|"
for scene in toy leine_glocker leine_glocker_drilling leine_glocker_twin mujoco_tutorial; do
  for horizon in scene 30; do
    row="| \`$scene\` | $horizon |"
    for run in analytic ode bullet mujoco-com mujoco-ball_centre dart; do
      args=(run "harness/scenes/$scene.toml" --engine "${run%%-*}" --out "$work/$scene-$horizon-$run")
      [ "$horizon" = 30 ] && args+=(--set run.duration=30)
      case "$run" in mujoco-*) args+=(--set "engines.mujoco.body_frame=\"${run#mujoco-}\"") ;; esac
      mkdir -p "$work/$scene-$horizon-$run"
      "$tippe" "${args[@]}" >"$work/stdout" 2>/dev/null
      mv "$work/stdout" "$work/$scene-$horizon-$run/stdout"
      row="$row $(cell "$work/$scene-$horizon-$run") |"
    done
    echo "$row"
  done
done
