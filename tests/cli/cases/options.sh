#!/usr/bin/env bash
# tests/cli/cases/options.sh -- the command-line conventions users bring (sim/cli/opts.h): getopt_long
# everywhere, so --set=KEY=V, -j2, --threads=2, options after operands and --version on every
# command work; every help has examples; compare's thresholds exit 6 for scripts.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFASM=${SFASM:-bin/sfasm}
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-options.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

version=$(tr -d ' \n\r\t' < VERSION)
TINY=(--mode reference --set render.width=8 --set render.height=8 --no-progress)

for cmd in run exec config compare trace sweep merge help; do
    begin "sfsim $cmd --version prints the version and exits 0"
    run "$SFSIM" "$cmd" --version
    want_rc 0; want_out "^sfsim $version \(commit "
    end
done

for cmd in run exec config compare trace sweep merge help; do
    begin "sfsim help $cmd shows examples"
    run "$SFSIM" help "$cmd"
    want_rc 0; want_out "^examples"
    end
done

begin "sfsim help lists every run mode, sampled included"
run "$SFSIM" help
want_rc 0
for m in detailed sampled functional reference; do want_out "$m"; done
end

begin "sfsim run --set=render.spp=2 -j2 --threads=2 as users type them"
run "$SFSIM" run "${TINY[@]}" --set=render.spp=2 -j2 -o "$T/a"
want_rc 0
grep -qE '"spp":[[:space:]]*2,' "$T/a/report.json" || no "report.json does not say spp 2"
run "$SFSIM" run "${TINY[@]}" --set=render.spp=2 --threads=2 -o"$T/b"
want_rc 0
cmp -s "$T/a/frame.exr" "$T/b/frame.exr" || no "the same run spelled two ways gave two images"
end

begin "sfsim run -o DIR/ prints DIR/frame.png, not DIR//frame.png"
run "$SFSIM" run "${TINY[@]}" --set render.spp=1 -o "$T/c/"
want_rc 0; want_out "wrote $T/c/frame.png"
grep -q '//' "$T/out" && no "a doubled slash: $(cat "$T/out")"
end

begin "an unknown option, a missing value and a value to a flag are usage errors (2) naming the option"
run "$SFSIM" run --no-such-option
want_rc 2; want_err "unknown or ambiguous option '--no-such-option'"
run "$SFSIM" run --set
want_rc 2; want_err "option '--set' needs a value"
run "$SFSIM" run --no-progress=1
want_rc 2; want_err "'--no-progress' takes no value"
run "$SFSIM" run -Z
want_rc 2; want_err "unknown option '-Z'"
run "$SFSIM" run extra-operand
want_rc 2; want_err "unexpected argument 'extra-operand'"
end

begin "an option value out of range is bad input (1)"
run "$SFSIM" run -j0
want_rc 1; want_err "-j 0: expected an integer in 1..1024"
run "$SFSIM" run --mode=fast
want_rc 1; want_err "--mode fast"
end

begin "a mode the machine cannot run is bad input (1), said before the scene is read (sim/cli/runopts.c)"
run "$SFSIM" run --mode sampled --set workload.kind=specular -s "$T/no_such_scene.ini" -o "$T/w"
want_rc 1
want_err "^sfsim run: --mode sampled: workload.kind = specular has no golden model to draw the units' auxiliary counts from \(path and phong do\); use --mode detailed$"
run "$SFSIM" run --mode reference --set workload.kind=diffuse -s "$T/no_such_scene.ini" -o "$T/w"
want_rc 1; want_err "^sfsim run: --mode reference: workload.kind = diffuse has no golden model \(path and phong do\)$"
[ -e "$T/w" ] && no "a refused run made its output folder"
run "$SFSIM" trace --mode sampled -s "$T/no_such_scene.ini" --rays tests/cli/cornell_rays.txt -o "$T/h"
want_rc 1; want_err "^sfsim trace: --mode sampled: expected functional, detailed or reference$"
end

begin "sfsim exec takes its options after the program too"
"$SFASM" tests/cli/ok.s -o "$T/ok.sfo" >/dev/null 2>&1 || no "cannot assemble tests/cli/ok.s"
run "$SFSIM" exec "$T/ok.sfo" -q --width=8
want_rc 0; want_out "on N = 8 lanes"
end

begin "sfasm -DNAME=V, --define=NAME=V, -oFILE and --output=FILE"
printf '.if X == 3\n  li r1, 7\n.endif\n  halt\n' > "$T/d.s"
run "$SFASM" "$T/d.s" -DX=3 -o"$T/d1.sfo"
want_rc 0
run "$SFASM" --define=X=3 --output="$T/d2.sfo" "$T/d.s"
want_rc 0
cmp -s "$T/d1.sfo" "$T/d2.sfo" || no "the two spellings gave two objects"
end

"$SFSIM" run "${TINY[@]}" --set render.spp=1 -o "$T/r1" >/dev/null 2>&1
"$SFSIM" run "${TINY[@]}" --set render.spp=2 -o "$T/r2" >/dev/null 2>&1

begin "sfsim compare with thresholds it meets exits 0"
run "$SFSIM" compare "$T/r1/frame.exr" "$T/r1/frame.exr" --max-rmse 0 --min-psnr 100 --max-diff=0
want_rc 0; want_out "RMSE"
end

begin "sfsim compare exits 6 naming the threshold exceeded, and still prints the figures"
run "$SFSIM" compare "$T/r1/frame.exr" "$T/r2/frame.exr" --max-rmse 1e-9
want_rc 6; want_err "--max-rmse 1e-09 exceeded: RMSE"; want_out "RMSE"
run "$SFSIM" compare --min-psnr=200 "$T/r1/frame.exr" "$T/r2/frame.exr"
want_rc 6; want_err "--min-psnr 200 exceeded"
run "$SFSIM" compare "$T/r1/frame.exr" "$T/r2/frame.exr" --max-diff abc
want_rc 1; want_err "--max-diff abc: expected a finite number"
end

cli_summary "cli options"
