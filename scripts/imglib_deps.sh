#!/usr/bin/env bash
# scripts/imglib_deps.sh LIB -- the shared libraries that LIB needs, each after every library it
# needs itself (a depth-first post-order of DT_NEEDED, resolved as ldd resolves them), one soname
# a line. The Makefile writes it beside the image library as libsfsim-img.so.deps; sim/imglib.c
# opens the libraries in this order before the image library, so that each one's relocations
# search its own dependencies rather than all ~260 of OpenImageIO's (docs/performance.md,
# "Start-up"). A stale list only costs speed: a name that no longer loads is skipped.
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: scripts/imglib_deps.sh LIB" >&2; exit 2; }
declare -A path seen
while read -r so arrow p _; do
    [ "$arrow" = "=>" ] && [ -f "$p" ] && path[$so]=$p
done < <(ldd "$1")
needed() { readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'; }
visit() {
    local so=$1 d
    [ -n "${seen[$so]:-}" ] && return
    seen[$so]=1
    [ -n "${path[$so]:-}" ] || return 0
    for d in $(needed "${path[$so]}"); do visit "$d"; done
    echo "$so"
}
for d in $(needed "$1"); do visit "$d"; done
