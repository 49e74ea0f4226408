#!/usr/bin/env bash
# Tests scripts/publish-guard.sh on a repository of its own: pages changed under reports/ (what an
# earlier publishing step wrote) pass, any other change or a tippe built at another commit refuses
# with exit 2. Usage: test_publish_guard.sh REPO_ROOT WORK_DIR
set -uo pipefail
src="$1"
work="$2"
rm -rf "$work"
mkdir -p "$work/repo/scripts" "$work/repo/reports/page" "$work/repo/harness"
cp "$src/scripts/publish-guard.sh" "$work/repo/scripts/"
cd "$work/repo" || exit 1
export GIT_CEILING_DIRECTORIES="$work"
g() { git -c user.email=test@example.invalid -c user.name=test "$@" >/dev/null; }
echo "{}" >reports/page/records.jsonl
echo "scene" >harness/scene.toml
g init -q
g add -A
g commit -q -m first
head="$(git rev-parse --short=12 HEAD)"
# A stand-in for the tippe binary: its --version names the commit given in $BUILT.
cat >"$work/tippe" <<'EOF'
#!/bin/sh
echo "tippe 0.1.0 (commit $BUILT, GNU 12.2.0)"
EOF
chmod +x "$work/tippe"

failures=0
# expect WANT WHAT: runs the guard as a publish script sources it and compares its exit status.
expect() {
  local want="$1" what="$2" got
  (root="$work/repo" tippe="$work/tippe" reports="$work/repo/reports"
   source "$work/repo/scripts/publish-guard.sh" test-guard) >/dev/null 2>"$work/stderr"
  got=$?
  if [ "$got" != "$want" ]; then
    echo "FAIL: $what: exit $got, want $want ($(cat "$work/stderr"))"
    failures=$((failures + 1))
  else
    echo "ok: $what: exit $got"
  fi
}

export BUILT="$head"
expect 0 "a clean checkout and a tippe built at HEAD"
echo '{"changed": 1}' >reports/page/records.jsonl
mkdir -p reports/new-page
echo "new" >reports/new-page/index.html
expect 0 "pages changed and added under reports/"
echo "changed" >harness/scene.toml
expect 2 "a tracked file changed outside reports/"
git checkout -q -- harness/scene.toml
echo "new" >harness/new.toml
expect 2 "an untracked file outside reports/"
rm harness/new.toml
BUILT="${head}-dirty" expect 2 "a tippe built from a tree with changes"
BUILT="0123456789ab" expect 2 "a tippe built at another commit"
echo "changed" >harness/scene.toml
REPORTS_DIR="$work/elsewhere" expect 0 "a trial run writing elsewhere (REPORTS_DIR)"
[ "$failures" = 0 ] || { echo "$failures case(s) failed"; exit 1; }
