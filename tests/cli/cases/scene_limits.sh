#!/usr/bin/env bash
# tests/cli/cases/scene_limits.sh -- scene values beyond the limits of the arithmetic they enter
# (docs/scenes.md, "Limits of scene values") are refused by name with exit 1 (EXIT_INPUT) and no
# output written, instead of rendering a black image with exit 0; a GLB whose header version is not
# 2 and a node matrix that is not affine likewise. The inputs are tests/scenes/bad_limit_*.
set -u
cd "$(dirname "$0")/../../.." || exit 2
SFSIM=${SFSIM:-bin/sfsim}
T=$(mktemp -d "${TMPDIR:-/tmp}/sfsim-cli-limits.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
. tests/cli/lib.sh

# refused FILE PATTERN: run FILE; exit 1, stderr matching PATTERN (which names the value), and
# nothing in the output folder.
refused() {
    rm -rf "$T/o"
    run "$SFSIM" run -s "tests/scenes/$1" -o "$T/o" --set render.width=8 --set render.height=8 \
        --set render.spp=1 --mode reference
    want_rc 1
    want_err "$2"
    if [ -d "$T/o" ] && [ -n "$(ls -A "$T/o")" ]; then
        no "files written to the output folder: $(ls -A "$T/o" | tr '\n' ' ')"
    fi
}

begin "a scene.ini point light of colour x intensity 1e37 is refused by line and key"
refused bad_limit_light_power.ini \
    "bad_limit_light_power.ini:7: key 'light.bulb.intensity': color x intensity is \(1e\+37, 1e\+37, 1e\+37\), beyond the limit of 1e\+36"
end

begin "a glTF point light of intensity 1e37 is refused by node and light"
refused bad_limit_light_power.gltf \
    "bad_limit_light_power.gltf: light 0 'bulb': color x intensity is \(1e\+37, 1e\+37, 1e\+37\), beyond the limit of 1e\+36"
end

begin "a scene.ini camera at 1e30 is refused"
refused bad_limit_camera_far.ini \
    "bad_limit_camera_far.ini:4: section \[camera\]: position is \(0, 0, 1e\+30\), beyond the limit of 1e\+18 on scene coordinates"
end

begin "a glTF camera at 1e30 is refused by node and camera"
refused bad_limit_camera_far.gltf \
    "bad_limit_camera_far.gltf: node 1 'far': camera 0 'eye': position is \(0, 0, 1e\+30\), beyond the limit of 1e\+18"
end

begin "a sphere of radius 1e20 is refused by line and key"
refused bad_limit_sphere_radius.ini \
    "bad_limit_sphere_radius.ini:8: key 'sphere.moon.radius': \|center\| \+ radius is \(1e\+20, 1e\+20, 1e\+20\), beyond the limit of 1e\+18"
end

begin "a NaN light intensity is refused by line and key"
refused bad_limit_nan.ini "bad_limit_nan.ini:7: key 'light.bulb.intensity': expected a number, got 'nan'"
end

begin "a quad light of area 4e18 is refused by section"
refused bad_limit_quad_area.ini \
    "bad_limit_quad_area.ini:4: section \[light.sky\]: the area \|edge_u x edge_v\| is 4e\+18, beyond the limit of 1e\+18 on areas"
end

begin "a glTF emission of strength 1e30 is refused by material"
refused bad_limit_emission.gltf \
    "bad_limit_emission.gltf: material 0 'paint': emission \(emissiveFactor x KHR_materials_emissive_strength\) is \(1e\+30, 1e\+30, 1e\+30\), beyond the limit of 1e\+18 on radiance"
end

begin "a triangle scaled to |e1 x e2| = 1e20 is refused by mesh, primitive and triangle"
refused bad_limit_big_triangle.gltf \
    "bad_limit_big_triangle.gltf: mesh 0 'tri' primitive 0: triangle 0 \(vertices 0, 1, 2\): \|e1 x e2\| is 1e\+20, beyond the limit of 1e\+18 on areas"
end

begin "a node matrix that is not affine is refused by node"
refused bad_limit_not_affine.gltf \
    "bad_limit_not_affine.gltf: node 0 'tri': matrix is not affine: its bottom row is \(0, 0, 0.5, 1\), not \(0, 0, 0, 1\) within 1e-06"
end

begin "a GLB whose header version is 1 is refused"
refused bad_limit_glb_version1.glb "bad_limit_glb_version1.glb: GLB header version 1, not 2"
end

begin "a base colour above 1 is a warning, not a refusal"
cat > "$T/bright.ini" <<EOF
[gltf.t]
file = $PWD/tests/scenes/ok_triangle.gltf
[material.paint]
base_color = 1.5 0.5 0.5
[light.bulb]
type = point
position = 0.2 0.2 2
EOF
rm -rf "$T/o"
run "$SFSIM" run -s "$T/bright.ini" -o "$T/o" --set render.width=8 --set render.height=8 --set render.spp=1 \
    --mode reference
want_rc 0
want_err "warning: .*bright.ini:4: key 'material.paint.base_color': is \(1.5, 0.5, 0.5\), beyond the limit of 1 on reflectances"
[ -s "$T/o/frame.exr" ] || no "no frame.exr written"
end

begin "a camera within the limits at the scene's size is refused at a size given on the command line that lengthens its rays"
run "$SFSIM" run -s tests/scenes/limit_camera_wide.ini -o "$T/cw" --set render.spp=1 --mode reference
want_rc 0
rm -rf "$T/cw"
run "$SFSIM" run -s tests/scenes/limit_camera_wide.ini -o "$T/cw" --set render.spp=1 --mode reference \
    --set render.width=16384 --set render.height=1
want_rc 1
want_err "limit_camera_wide.ini: the camera at 16384 x 1: ray length .* beyond the limit of 1e\+19"
[ ! -e "$T/cw" ] || no "an output folder was made"
end

begin "an MTL emission beyond the limit on radiance is refused naming the file and material"
printf 'newmtl hot\nKd 0.5 0.5 0.5\nKe 1e30 1 1\n' > "$T/hot.mtl"
printf 'mtllib hot.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n' > "$T/hot.obj"
run "$SFSIM" run -s "$T/hot.obj" -o "$T/hot" --set render.width=8 --set render.height=8 --set render.spp=1 --mode reference
want_rc 1
want_err "hot.mtl: material 'hot': Ke is \(1e\+30, 1, 1\), beyond the limit of 1e\+18 on radiance"
end

cli_summary "cli scene_limits"
