#!/usr/bin/env bash
# tests/cli/cases/obj.sh -- Wavefront OBJ + MTL scenes end to end (docs/scenes.md, OBJ and MTL): the
# same scene as OBJ and as glTF renders the same image in every mode; `-s x.obj` works as `-s
# x.gltf` does; bad OBJ files exit 1 naming the file and line; a scene.ini whose mesh file is
# missing is refused, saying where the scene comes from, by `sfsim run` and by `sfsim sweep` before
# its first point. Renders are 16 x 16 at 1 sample: a few seconds in all.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-obj.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

O=tests/scenes/obj

# ---- the same scene, two formats, every mode -----------------------------------------------------

for mode in reference functional detailed sampled; do
    extra=()
    [ "$mode" = sampled ] && extra=(--sample 0.5)
    begin "cross-obj.ini renders the same frame.exr as cross-gltf.ini in $mode mode"
    run "$SFSIM" run -s $O/cross-gltf.ini -o "$T/g-$mode" --mode $mode "${extra[@]}" -j 2 --no-progress
    want_rc 0
    run "$SFSIM" run -s $O/cross-obj.ini -o "$T/o-$mode" --mode $mode "${extra[@]}" -j 2 --no-progress
    want_rc 0
    [ -s "$T/g-$mode/frame.exr" ] || no "no frame.exr from the glTF scene"
    cmp -s "$T/g-$mode/frame.exr" "$T/o-$mode/frame.exr" || no "frame.exr differs between the OBJ and the glTF scene"
    end
done

begin "the image is not the plain Cornell box: the mirror and glass walls change it (the test can fail)"
run "$SFSIM" run -s scenes/cornell/cornell-box.gltf -o "$T/plain" --mode reference --set render.width=16 \
    --set render.height=16 --set render.spp=1 -j 2 --no-progress
want_rc 0
cp "$T/g-reference/frame.exr" "$T/cross.exr" 2>/dev/null
# same camera as cross-*.ini: the glTF has none, so the default camera would differ; render the
# plain box through cross-gltf.ini without its overrides instead
grep -v -e '^\[material' -e '^kind' -e '^metallic' -e '^roughness' -e '^base_color' -e '^ior' $O/cross-gltf.ini |
    sed "s|^gltf = .*|gltf = $PWD/scenes/cornell/cornell-box.gltf|" >"$T/plain.ini"
run "$SFSIM" run -s "$T/plain.ini" -o "$T/plain2" --mode reference -j 2 --no-progress
want_rc 0
cmp -s "$T/plain2/frame.exr" "$T/cross.exr" && no "the mirror and glass overrides did not change the image"
end

begin "-s x.obj directly: loads with the default camera and renders"
run "$SFSIM" run -s $O/box.obj -o "$T/box" --mode reference --set render.width=8 --set render.height=8 \
    --set render.spp=1 -j 2 --no-progress
want_rc 0
[ -s "$T/box/frame.exr" ] || no "no frame.exr"
grep -qE '"needs":[[:space:]]*\["lambert", "glossy", "dielectric", "area_lights"\]' "$T/box/report.json" 2>/dev/null ||
    no "report.json lacks the needs lambert, glossy, dielectric, area_lights"
end

# ---- refused inputs: exit 1 (EXIT_INPUT), the file and the line ---------------------------------

bad() { # bad FILE PATTERN: sfsim run -s FILE exits 1 with PATTERN on stderr
    begin "-s $1: refused with exit 1: /$2/"
    run "$SFSIM" run -s "$1" -o "$T/bad" --mode reference -j 1 --no-progress
    want_rc 1
    want_err "$2"
    end
}
bad $O/bad_missing_mtl.obj "bad_missing_mtl.obj:2: mtllib 'nothere.mtl': .*cannot open"
bad $O/bad_missing_texture.obj "bad_missing_texture.mtl: material 'textured' map_Kd 'nothere.png': .*cannot open"
bad $O/bad_empty_face.obj "bad_empty_face.obj:5: face with 0 vertices"
bad $O/bad_1000_face.obj "bad_1000_face.obj:1002: face with 1000 vertices"
bad $O/bad_index_out_of_range.obj "bad_index_out_of_range.obj:5: vertex index 4 out of range"
bad $O/bad_no_faces.obj "bad_no_faces.obj: no faces"
mkdir -p "$T/dir.obj"
bad "$T/dir.obj" "dir.obj: is a directory, not a regular file"
bad /dev/zero "unknown scene type"
ln -s /dev/zero "$T/zero.obj"
bad "$T/zero.obj" "zero.obj: not a regular file"

# ---- a missing mesh file: where to get the scene --------------------------------------------------

begin "sfsim run -s a scene.ini whose mesh is missing: exit 1, names the file and where to get the scene"
run "$SFSIM" run -s $O/missing-mesh.ini -o "$T/missing" --mode reference -j 1 --no-progress
want_rc 1
want_err "missing-mesh.ini:4: key 'scene.gltf': .*not-downloaded/conference.obj: cannot open"
want_err "where to get the scene: McGuire Computer Graphics Archive"
end

begin "sfsim sweep with that scene: refused before any point runs (no point folder), saying where to get it"
printf '[sweep]\ncore.simd_width = 8, 16\n' >"$T/sw.ini"
run "$SFSIM" sweep --sweep "$T/sw.ini" -s $O/missing-mesh.ini -o "$T/sweep" --mode functional -j 1
want_rc 1
want_err "missing-mesh.ini:4: key 'scene.gltf': .*cannot open"
want_err "where to get the scene: McGuire"
want_err "nothing was run"
[ -e "$T/sweep/points/000" ] && no "a point folder was created"
end

cli_summary "cli obj"
