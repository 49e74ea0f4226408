#!/usr/bin/env bash
# Sourced by the publish scripts: refuses (exit 2) to write the repository's published pages from a working tree with changes outside reports/, or with a tippe built from another commit than HEAD, so that every record names the clean commit whose code made it.
# Usage (after `tippe` and `reports` are set): source "$root/scripts/publish-guard.sh" NAME
publish_guard() {
  local name="$1" head built
  # Writing elsewhere (REPORTS_DIR) is a trial run: no record there is published.
  [ -n "${REPORTS_DIR:-}" ] && return 0
  # Pages under reports/ are what publishing writes, not code: publish-all's later steps run after
  # its earlier ones have written there. Any other change refuses.
  if [ -n "$(git -C "$root" status --porcelain --untracked-files=normal -- . ':(exclude)reports' 2>/dev/null)" ]; then
    echo "$name: the working tree has changes outside reports/ (git status): publish from a clean checkout of a commit" >&2
    exit 2
  fi
  head="$(git -C "$root" rev-parse --short=12 HEAD 2>/dev/null || true)"
  # `tippe --version` names the commit its build was made from: "tippe X (commit C, ...)", C
  # ending in "-dirty" when the tree had changes then (cmake/provenance.cmake).
  built="$("$tippe" --version 2>/dev/null | sed -n '1s/.*(commit \([0-9a-z-]*\).*/\1/p')"
  if [ -z "$head" ] || [ "$built" != "$head" ]; then
    echo "$name: $tippe was built at commit ${built:-unknown}, HEAD is ${head:-unknown}: rebuild it (cmake --build ${tippe%/tippe} --target tippe) so its records name the commit that made them" >&2
    exit 2
  fi
}
publish_guard "$1"
