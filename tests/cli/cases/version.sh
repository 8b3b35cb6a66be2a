#!/usr/bin/env bash
# tests/cli/cases/version.sh -- one version for sfsim and sfasm (the file VERSION), with the commit.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-version.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

want=$(tr -d ' \n\r\t' < VERSION)

begin "sfsim --version prints the version of the file VERSION and a commit"
run "$SFSIM" --version
want_rc 0; want_out "^sfsim $want \(commit ([0-9a-f]{12}(-dirty)?|unknown)\)"
end

begin "sfasm --version prints the same version"
run "$SFASM" --version
want_rc 0; want_out "^sfasm $want \(commit "
end

cli_summary "cli version"
