#!/usr/bin/env bash
# tests/kernel_identity.sh -- the path-tracing kernel assembles to the same program as a reference
# tree's kernel, for every -D combination the simulator uses (sim/run/kernel.c builds the list):
# the workloads, BVH (ray and first order) and the six kd-tree variants, TRACE_ONLY, each HAS_*
# feature alone and all together, and several stream sizes (RAYS 1024, 4096; packet mode's N).
#
# It compares the object's TEXT, DATA and SPAD payloads byte for byte, and checks that every
# constant of the reference object (the host reads its interface from them, docs/kernel.md) is in
# the new object with the same value. FILES, LINES and labels may differ: a refactor moves lines
# between files. It owns no build: pass the two trees.
#
#   bash tests/kernel_identity.sh [REF_SFASM REF_KERNELS_DIR]     (defaults: /work/baseline)
#   QUICK=1 bash tests/kernel_identity.sh                         (RAYS 1024 only)
set -uo pipefail
cd "$(dirname "$0")/.."
REF_SFASM=${1:-/work/baseline/bin/sfasm}
REF_KERNELS=${2:-/work/baseline/kernels}
NEW_SFASM=${NEW_SFASM:-bin/sfasm}
NEW_KERNELS=${NEW_KERNELS:-kernels}
for f in "$REF_SFASM" "$NEW_SFASM"; do [ -x "$f" ] || { echo "kernel identity: no $f"; exit 2; }; done
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-kid.XXXXXX")
trap 'rm -rf "$T"' EXIT

# Object $1 as text: the words of its TEXT, DATA and SPAD payloads ("s<kind> <words>" lines) and
# its constants (section-0 symbols: "c <name> <value>"), constants sorted. Payload sizes are
# multiples of 4 in these kernels (no .byte data), and every payload starts 8-byte aligned.
dump() {
    od -An -v -tu4 "$1" | awk '
    { for (i = 1; i <= NF; i++) w[n++] = $i }
    END {
        for (s = 0; s < w[2]; s++) {
            kind = w[4 + 4 * s]; off = w[5 + 4 * s] / 4; size = w[6 + 4 * s] / 4
            if (kind >= 1 && kind <= 3) {
                line = "s" kind
                for (j = 0; j < size; j++) line = line " " w[off + j]
                print line
            } else if (kind == 6) {
                for (p = off; p < off + size; ) {
                    len = w[p + 2]; name = ""
                    for (k = 0; k < len; k++) name = name sprintf("%c", int(w[p + 3 + int(k / 4)] / 256 ^ (k % 4)) % 256)
                    if (w[p] == 0) print "c " name " " w[p + 1] | "sort"
                    p += 3 + int((len + 3) / 4)
                }
            }
        }
    }'
}

FEATURES=(HAS_LAMBERT HAS_GLOSSY HAS_DIELECTRIC HAS_TEXTURES HAS_EMISSIVE_TEX HAS_COLORS HAS_NORMALS
          HAS_SPHERES HAS_PUNCTUAL HAS_BACKGROUND HAS_AMBIENT)
FEATSETS=("" "${FEATURES[@]}" "${FEATURES[*]}" "HAS_LAMBERT HAS_GLOSSY" "HAS_LAMBERT HAS_AMBIENT"
          "HAS_GLOSSY HAS_EMISSIVE_TEX HAS_PUNCTUAL" "HAS_SPHERES HAS_TEXTURES HAS_NORMALS HAS_COLORS")
WORKLOADS=("" "WORKLOAD=1 BOUNCES=1" "WORKLOAD=1 BOUNCES=3" "WORKLOAD=2" "WORKLOAD=3 BOUNCES=0" "WORKLOAD=3 BOUNCES=1")
ACCELS=("" "ORDER_FIRST")
for v in 0 1 2 3 4 5; do ACCELS+=("ACCEL_KD KD_VARIANT=$v KD_STACK_DEPTH=8"); done
ACCELS+=("ACCEL_KD KD_VARIANT=3 KD_STACK_DEPTH=1" "ACCEL_KD KD_VARIANT=0 KD_STACK_DEPTH=64"
         "ACCEL_KD KD_VARIANT=5 KD_STACK_DEPTH=1 ORDER_FIRST")
if [ -n "${QUICK:-}" ]; then RAYSET=(1024); else RAYSET=(1024 4096 16 8); fi

defs() { local d; for d in "$@"; do printf -- '-D %s ' "$d"; done; }

fail=0 n=0 bad=0
for rays in "${RAYSET[@]}"; do
    for wl in "${WORKLOADS[@]}"; do
        for acc in "${ACCELS[@]}"; do
            for tr in "" TRACE_ONLY; do
                for fs in "${FEATSETS[@]}"; do
                    # each feature alone only with the BVH and the kd variants with their own
                    # intersection code (stream, packet, per lane); 4096 and the packet sizes
                    # with no features and with all of them
                    if [ "$fs" != "" ] && [ "$fs" != "${FEATURES[*]}" ]; then
                        [ "$rays" = 1024 ] || continue
                        case "$acc" in "" | *VARIANT=[045]\ *KD_STACK_DEPTH=8) ;; *) continue ;; esac
                    fi
                    # shellcheck disable=SC2206
                    set -- RAYS=$rays SPAD_BYTES=65536 $wl $acc $tr $fs
                    D=$(defs "$@")
                    n=$((n + 1))
                    # shellcheck disable=SC2086
                    "$REF_SFASM" $D -I "$REF_KERNELS/lib" "$REF_KERNELS/pathtrace.s" -o "$T/ref.sfo" 2>"$T/ref.err"
                    rr=$?
                    # shellcheck disable=SC2086
                    "$NEW_SFASM" $D -I "$NEW_KERNELS/lib" "$NEW_KERNELS/pathtrace.s" -o "$T/new.sfo" 2>"$T/new.err"
                    nr=$?
                    if [ $rr -ne 0 ] || [ $nr -ne 0 ]; then
                        if [ $rr -ne $nr ]; then
                            echo "DIFF (assembles: ref rc $rr, new rc $nr): $*"; head -3 "$T/ref.err" "$T/new.err"
                            fail=$((fail + 1))
                        else
                            bad=$((bad + 1))  # neither assembles (not a combination the host makes)
                        fi
                        continue
                    fi
                    dump "$T/ref.sfo" > "$T/ref.txt"
                    dump "$T/new.sfo" > "$T/new.txt"
                    if ! cmp -s <(grep '^s' "$T/ref.txt") <(grep '^s' "$T/new.txt"); then
                        echo "DIFF (TEXT, DATA or SPAD): $*"; fail=$((fail + 1)); continue
                    fi
                    missing=$(comm -23 <(grep '^c' "$T/ref.txt") <(grep '^c' "$T/new.txt"))
                    if [ -n "$missing" ]; then
                        echo "DIFF (constants missing or changed): $*"; echo "$missing" | head -5
                        fail=$((fail + 1))
                    fi
                done
            done
        done
    done
done
echo "kernel identity: $n combinations, $((n - fail - bad)) identical, $bad assemble in neither tree"
echo "$((n - fail)) passed, $fail failed"
[ "$fail" -eq 0 ]
