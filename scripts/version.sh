#!/usr/bin/env bash
# Prints the C header that names this build: the version (the file VERSION, one for sfsim and
# sfasm) and the commit it was built from (git's, "-dirty" when the tree had changes; "unknown"
# outside a git checkout, as in a release tarball). The Makefile rewrites build/gen/version_gen.h
# with it only when it changed, so a new commit rebuilds host/version.o and nothing else.
set -u
cd "$(dirname "$0")/.." || exit 1
version=$(tr -d ' \n\r\t' < VERSION 2>/dev/null)
[ -n "$version" ] || version=unknown
commit=unknown
if git rev-parse --is-inside-work-tree >/dev/null 2>&1 && c=$(git rev-parse --short=12 HEAD 2>/dev/null); then
    commit=$c
    git diff --quiet HEAD -- 2>/dev/null || commit="$commit-dirty"
fi
printf '#define SFSIM_VERSION_STRING "%s"\n#define SFSIM_COMMIT_STRING "%s"\n' "$version" "$commit"
