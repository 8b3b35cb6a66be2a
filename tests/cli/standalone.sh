#!/usr/bin/env bash
# tests/cli/standalone.sh -- the repository on its own: the shipped Cornell box is what
# tools/gen_cornell.c writes, bin/sfsim finds its kernel and default scene from any folder, and
# `make install PREFIX=...` gives a tree whose sfsim works from any folder, with no source tree
# and no ../shared; sfsim writes its images itself (OpenEXR, libpng, FreeType linked in) and loads
# its image library (lib/sfsim/libsfsim-img.so, OpenImageIO's reader) from beside its folder only
# when it reads images (`sfsim compare`), and says clearly when it cannot (sim/imglib.h). `make test` runs it (SFSIM_GEN_CORNELL names the generator it built).
# Exit status: 0 when every case passed.
set -u

cd "$(dirname "$0")/../.." || exit 2
ROOT=$(pwd)
SFSIM=$ROOT/bin/sfsim
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-standalone.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
SMALL=(--set render.width=32 --set render.height=32 --set render.spp=1 --no-progress)

. tests/cli/lib.sh
# scene_file DIR: the scene file a run's report.json names
scene_file() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["scene"]["file"])' "$1/report.json" 2>/dev/null; }

begin "the shipped Cornell box is what tools/gen_cornell.c writes (make docs)"
if [ -x "${SFSIM_GEN_CORNELL:-}" ]; then
    mkdir -p "$T/gen"
    if "$SFSIM_GEN_CORNELL" "$T/gen" 2>"$T/err"; then
        for f in cornell-box.gltf cornell-box.bin; do
            cmp -s "$T/gen/$f" "scenes/cornell/$f" || no "scenes/cornell/$f is stale: run make docs"
        done
    else
        no "gen_cornell failed"
    fi
else
    no "SFSIM_GEN_CORNELL is not set to the built generator (make test sets it)"
fi
end

begin "the shipped scenes need nothing outside the repository"
for f in scenes/cornell/scene.ini scenes/cornell/glossy.ini scenes/cornell/analytic.ini; do
    grep -q "shared/" "$f" && no "$f refers to ../shared"
done
end

begin "bin/sfsim run with no -s renders the shipped Cornell box from /"
run env -C / "$SFSIM" run -o "$T/from-root" "${SMALL[@]}"
want_rc 0
[ -s "$T/from-root/frame.png" ] || no "no frame.png"
[ "$(scene_file "$T/from-root")" = "$ROOT/scenes/cornell/scene.ini" ] ||
    no "report.json names scene '$(scene_file "$T/from-root")', expected $ROOT/scenes/cornell/scene.ini"
end

begin "bin/sfsim run --mode functional from another folder finds its kernel"
mkdir -p "$T/elsewhere"
run env -C "$T/elsewhere" "$SFSIM" run --mode functional -o out "${SMALL[@]}"
want_rc 0
[ -s "$T/elsewhere/out/frame.exr" ] || no "no frame.exr"
end

begin "bin/sfsim sweep with no -s sweeps the shipped Cornell box from another folder"
printf '[sweep]\ncore.simd_width = 8, 16\n' > "$T/elsewhere/two.ini"
run env -C "$T/elsewhere" "$SFSIM" sweep --sweep two.ini -o sw -j 2 --mode functional \
    --set render.width=32 --set render.height=32 --set render.spp=1
want_rc 0
[ "$(grep -c . "$T/elsewhere/sw/sweep.csv" 2>/dev/null)" = 3 ] || no "sweep.csv does not hold a header and 2 points"
end

begin "make install PREFIX=... installs binaries, kernels, configs, the default scene and docs"
run make --no-print-directory install PREFIX="$T/prefix"
want_rc 0
for f in bin/sfsim bin/sfasm lib/sfsim/libsfsim-img.so lib/sfsim/libsfsim-img.so.deps share/sfsim/kernels/pathtrace.s share/sfsim/kernels/lib/layout.inc \
    share/sfsim/kernels/lib/kconst.inc share/sfsim/kernels/lib/frames.inc share/sfsim/kernels/filters/traverse.inc \
    share/sfsim/configs/streamray.ini share/sfsim/configs/sweeps/width.ini share/sfsim/scenes/cornell/scene.ini \
    share/sfsim/scenes/cornell/cornell-box.gltf share/sfsim/scenes/cornell/cornell-box.bin \
    share/doc/sfsim/README.md share/doc/sfsim/LICENSE share/doc/sfsim/docs/README.md; do
    [ -s "$T/prefix/$f" ] || no "$f is not installed"
done
end

begin "the installed sfsim renders the default scene from another folder, with its own files"
mkdir -p "$T/user"
run env -C "$T/user" "$T/prefix/bin/sfsim" run -o out "${SMALL[@]}"
want_rc 0
[ -s "$T/user/out/frame.png" ] || no "no frame.png"
[ "$(scene_file "$T/user/out")" = "$T/prefix/share/sfsim/scenes/cornell/scene.ini" ] ||
    no "report.json names scene '$(scene_file "$T/user/out")', not the installed one"
end

begin "the installed sfsim compares with the installed image library; its run loads no OpenImageIO; it links none"
run env -C "$T/user" LD_DEBUG=files "$T/prefix/bin/sfsim" run --mode reference -o out-ld "${SMALL[@]}"
want_rc 0
grep -q "OpenImageIO\|libsfsim-img" "$T/err" && no "sfsim run loaded OpenImageIO: $(grep -m1 'OpenImageIO\|libsfsim-img' "$T/err")"
[ -s "$T/user/out-ld/frame.png" ] || no "no frame.png"
run env -C "$T/user" LD_DEBUG=files "$T/prefix/bin/sfsim" compare out-ld/frame.exr out/frame.exr
want_rc 0
want_out "RMSE"
grep -q "file=$T/prefix/lib/sfsim/libsfsim-img.so " "$T/err" || no "the installed library was not the one loaded"
grep -q "file=$ROOT/lib/sfsim/" "$T/err" && no "the build tree's library was loaded"
readelf -d "$T/prefix/bin/sfsim" | grep -q "NEEDED.*OpenImageIO" && no "sfsim links OpenImageIO"
end

begin "the installed sfsim takes the installed machine config and a scene by path"
run env -C "$T/user" "$T/prefix/bin/sfsim" run --mode reference -c "$T/prefix/share/sfsim/configs/streamray.ini" \
    -s "$T/prefix/share/sfsim/scenes/cornell/glossy.ini" -o out2 "${SMALL[@]}"
want_rc 0
[ -s "$T/user/out2/frame.exr" ] || no "no frame.exr"
end

begin "the installed sfasm assembles an installed example"
run "$T/prefix/bin/sfasm" "$T/prefix/share/sfsim/kernels/examples/filter_demo.s" -o "$T/user/demo.sfo"
want_rc 0
[ -s "$T/user/demo.sfo" ] || no "no object written"
end

begin "an sfsim without its data files says what is missing (exit 1), no crash"
mkdir -p "$T/lonely/bin"
cp "$SFSIM" "$T/lonely/bin/sfsim"
run env -C "$T/lonely" "$T/lonely/bin/sfsim" run -o out "${SMALL[@]}"
want_rc 1
want_err "data files are missing|default scene is missing"
[ -e "$T/lonely/out" ] && no "an output folder was left behind"
end

begin "SFSIM_DATA_DIR points sfsim at another data folder (and SFSIM_IMG_LIB at the image library)"
run env -C "$T/lonely" SFSIM_DATA_DIR="$T/prefix/share/sfsim" SFSIM_IMG_LIB="$T/prefix/lib/sfsim/libsfsim-img.so" "$T/lonely/bin/sfsim" run --mode reference -o out "${SMALL[@]}"
want_rc 0
[ -s "$T/lonely/out/frame.png" ] || no "no frame.png"
end

begin "an sfsim without its image library still runs (it writes its images itself); compare names the path it tried (exit 4)"
run env -C "$T/lonely" SFSIM_DATA_DIR="$T/prefix/share/sfsim" "$T/lonely/bin/sfsim" run -o out-noimg "${SMALL[@]}"
want_rc 0
for f in frame.exr frame.png cost.png; do [ -s "$T/lonely/out-noimg/$f" ] || no "no $f"; done
run env -C "$T/lonely" "$T/lonely/bin/sfsim" compare "$T/lonely/out/frame.exr" "$T/lonely/out/frame.exr"
want_rc 4
want_err "cannot load the image library $T/lonely/lib/sfsim/libsfsim-img.so"
end

begin "an image library that does not load is named with the loader's reason (exit 4); a run does not need it"
printf 'not a shared object\n' > "$T/bogus.so"
run env SFSIM_IMG_LIB="$T/bogus.so" "$SFSIM" run -o "$T/out-bogus" "${SMALL[@]}"
want_rc 0
[ -s "$T/out-bogus/frame.exr" ] || no "no frame.exr"
run env SFSIM_IMG_LIB="$T/bogus.so" "$SFSIM" compare "$T/out-bogus/frame.exr" "$T/out-bogus/frame.exr"
want_rc 4
want_err "cannot load the image library $T/bogus.so: .*(ELF|too short)"
run env SFSIM_IMG_LIB=/lib/x86_64-linux-gnu/libm.so.6 "$SFSIM" compare "$T/from-root/frame.exr" "$T/from-root/frame.exr"
want_rc 4
want_err "libm.so.6: it has no img_shim table"
end

begin "a compare that loaded the image library ends with _exit: its figures still reach stdout, no library's fini runs"
# sim/main.c: exit would run the destructors of OpenImageIO's ~265 libraries (docs/performance.md,
# "Start-up"). stdout is a file here, so the figures are in stdio's buffer until main flushes it.
run env LD_DEBUG=files "$SFSIM" run -o "$T/out-exit" "${SMALL[@]}"
want_rc 0
want_out "^sfsim run: wrote $T/out-exit/frame.png, frame.exr, report.txt, report.json, stats.txt, cost.png$"
[ -s "$T/out-exit/cost.png" ] || no "no cost.png"
run env LD_DEBUG=files "$SFSIM" compare "$T/out-exit/frame.png" "$T/out-exit/frame.png"
want_rc 0
want_out "RMSE +0$"
grep -q "file=.*libOpenImageIO" "$T/err" || no "compare did not load OpenImageIO (the test no longer tests _exit)"
grep -q "calling fini" "$T/err" && no "destructors ran at exit: $(grep -m1 'calling fini' "$T/err")"
run env LD_DEBUG=files "$SFSIM" run -s "$T/no-such-scene.ini" -o "$T/out-exit2" "${SMALL[@]}"
want_rc 1
want_err "no-such-scene.ini: cannot open"
[ -e "$T/out-exit2" ] && no "an output folder was left behind"
end

begin "commands that read no image never load the image library (help, config, exec, trace, run)"
run_ld() { run env SFSIM_IMG_LIB=/nonexistent/lib.so LD_DEBUG=files "$@"; want_rc 0; grep -q "OpenImageIO\|libsfsim-img" "$T/err" && no "$2 loaded the image library"; }
run_ld "$SFSIM" --help
run_ld "$SFSIM" config --dump
"$ROOT/bin/sfasm" kernels/examples/filter_demo.s -o "$T/demo.sfo" || no "sfasm failed"
run_ld "$SFSIM" exec "$T/demo.sfo"
run_ld "$SFSIM" trace -s scenes/cornell/scene.ini --rays tests/cli/cornell_rays.txt -o "$T/hits.txt"
run_ld "$SFSIM" run -o "$T/out-noload" "${SMALL[@]}"
end

begin "make uninstall PREFIX=... removes what make install put there, and nothing else"
touch "$T/prefix/bin/other-tool"
run make --no-print-directory uninstall PREFIX="$T/prefix"
want_rc 0
for f in bin/sfsim bin/sfasm lib/sfsim share/sfsim share/doc/sfsim; do
    [ ! -e "$T/prefix/$f" ] || no "$f is still there"
done
[ -e "$T/prefix/bin/other-tool" ] || no "a file make install did not put there was removed"
end

cli_summary standalone
