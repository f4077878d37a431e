#!/bin/sh
# test_robustness.sh — the bad-input table (docs/robustness.md): every hostile input class given to the
# real programs (rouge render, rouge view, rouge-pack, rouge-imgdiff, the shader embedder) gets ONE line
# on stderr naming the problem, a non-zero exit status (no crash: no signal), and leaves no output file
# and no temp file behind. Complements tests/test_cli.sh and tests/test_pack_cli.sh (usage errors there
# are not repeated here) and the loaders' unit tests (every truncation and bit flip of small files).
#
# Usage: sh tests/test_robustness.sh BUILD_DIR [NAME_FILTER...]   (run from the repository root)
# RS_ROBUSTNESS_TABLE=FILE also writes the table rows (input | command | what it gets) to FILE: that is
# how docs/robustness.md is made.
build=${1:-build}
[ $# -gt 0 ] && shift
filters="$*"
rouge="$build/rouge"
pack="$build/rouge-pack"
imgdiff="$build/rouge-imgdiff"
embed="$build/embed_shaders"
bad=tests/fixtures/bad
face=assets/face.rsf
tiny=tests/fixtures/rsf/tiny_v1.rsf
table=${RS_ROBUSTNESS_TABLE:-}
tmp=$(mktemp -d)
trap 'chmod -R u+w "$tmp" 2>/dev/null; rm -rf "$tmp"' EXIT
[ -n "$table" ] && : >"$table"

selected() {
    [ -z "$filters" ] && return 0
    for f in $filters; do
        case "$1" in *"$f"*) return 0 ;; esac
    done
    return 1
}

# bad_input NAME WHAT WANT_RC PATTERN OUTPUT CMD...
#   Runs CMD; wants exit WANT_RC, exactly one stderr line containing PATTERN, and neither OUTPUT nor any
#   OUTPUT.tmp* left behind ("-" when the command writes no file). WHAT describes the input for the table.
bad_input() {
    name=robust_$1 what=$2 want=$3 pat=$4 output=$5
    shift 5
    selected "$name" || return 0
    case $1 in render | env) prog=$rouge ;; bounded) prog=$2 ;; *) prog=$1 ;; esac
    if [ ! -x "$prog" ]; then
        echo "skip - $name: $prog not built"
        return 0
    fi
    # What an earlier case wrote there must not count against this one.
    [ "$output" != - ] && rm -f "$output" "$output".tmp*
    "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    lines=$(wc -l <"$tmp/err")
    why=""
    if [ "$rc" -ge 128 ]; then
        why="killed by signal $((rc - 128))"
    elif [ "$rc" -ne "$want" ]; then
        why="exit $rc, wanted $want"
    elif [ "$lines" -ne 1 ]; then
        why="stderr has $lines lines, wanted one"
    elif ! grep -qF -- "$pat" "$tmp/err"; then
        why="stderr lacks '$pat'"
    elif [ "$output" != - ] && { [ -e "$output" ] || ls "$output".tmp* >/dev/null 2>&1; }; then
        why="left $output (or a temp file) behind"
    fi
    if [ -n "$why" ]; then
        echo "FAIL - $name: $why: $(head -c 300 "$tmp/err")"
    else
        echo "ok - $name"
    fi
    if [ -n "$table" ]; then
        # The command as a reader would type it: scratch paths shortened, the build dir as "build".
        cmd=$(printf '%s ' "$@" | sed -e "s#$tmp/#/tmp/#g" -e "s#^render #build/rouge render #" -e "s#^bounded ##" \
            -e "s#\(^\| \)$build/#\1build/#g" -e 's/ $//')
        msg=$(head -n 1 "$tmp/err" | sed -e "s#$tmp/#/tmp/#g" -e 's/|/\\|/g')
        printf '| %s | `%s` | exit %s: `%s` |\n' "$what" "$cmd" "$rc" "$msg" >>"$table"
    fi
}

# warns_and_converts NAME WHAT PATTERN CMD...: a flaw that must not stop a conversion (a texture): wants
#   exit 0, a "warning:" line on stderr containing PATTERN and the $tmp/w.rsf that CMD writes (removed).
warns_and_converts() {
    name=robust_$1 what=$2 pat=$3
    shift 3
    selected "$name" || return 0
    rm -f "$tmp/w.rsf"
    "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    why=""
    if [ "$rc" -ne 0 ]; then
        why="exit $rc, wanted 0"
    elif ! grep "warning:" "$tmp/err" | grep -qF -- "$pat"; then
        why="no warning with '$pat'"
    elif [ ! -s "$tmp/w.rsf" ]; then
        why="no output written"
    fi
    if [ -n "$why" ]; then echo "FAIL - $name: $why: $(head -c 300 "$tmp/err")"; else echo "ok - $name"; fi
    if [ -n "$table" ]; then
        cmd=$(printf '%s ' "$@" | sed -e "s#$tmp/#/tmp/#g" -e "s#^bounded ##" -e "s#\(^\| \)$build/#\1build/#g" -e 's/ $//')
        msg=$(grep "warning:" "$tmp/err" | head -n 1 | sed -e "s#$tmp/#/tmp/#g" -e 's/|/\\|/g')
        printf '| %s | `%s` | exit %s (converted in grey): `%s` |\n' "$what" "$cmd" "$rc" "$msg" >>"$table"
    fi
    rm -f "$tmp/w.rsf"
}

# Hostile inputs run with bounded memory and time: a bomb that is not refused fails the test instead of
# taking the machine (2 GB of address space, 60 s). Not the address space under AddressSanitizer (make
# asan), which reserves terabytes of it up front.
asan_build=$(ldd "$pack" 2>/dev/null | grep -c libasan)
bounded() {
    if [ "$asan_build" -gt 0 ]; then timeout 60 "$@"; else (ulimit -v 2000000 && exec timeout 60 "$@"); fi
}

# The smallest render that still loads the whole face and makes a GL context. The mobile pipeline: the
# cases here test input handling, not the renderer, and its render costs ~0.5 CPU-s where the reference
# pipeline's shaders cost ~3.5 (the six cases that render to the end made half of this script's CPU).
render() {
    "$rouge" render "$@" --size 32x32 --max-splats 2000 --pipeline mobile
}

# ---- .rsf: truncated at every section (tiny_v1.rsf: header 0..624, records 624..688, CRC 688..692) ----
for cut in 0:empty 3:magic 10:fixed_header 150:lod_table 400:region_table 600:notes 620:padding \
    650:payload 690:crc; do
    n=${cut%%:*} section=${cut#*:}
    head -c "$n" "$tiny" >"$tmp/cut_$section.rsf"
    what=".rsf truncated in the $(echo "$section" | tr _ ' ') (first $n of 692 bytes)"
    [ "$n" = 0 ] && what=".rsf: empty file"
    bad_input "rsf_truncated_in_$section" "$what" 1 \
        "cut_$section.rsf:" "$tmp/o.png" "$rouge" render "$tmp/cut_$section.rsf" -o "$tmp/o.png"
done

# ---- .rsf: one damaged field each, CRC recomputed (tests/fixtures/bad/make_bad.py) ----
while IFS='|' read -r file pat what; do
    bad_input "${file%.rsf}" ".rsf: $what" 1 "$pat" "$tmp/o.png" "$rouge" render "$bad/$file" -o "$tmp/o.png"
done <<'EOF'
rsf_wrong_magic.rsf|magic:|wrong magic "RSX\0"
rsf_version_9.rsf|unsupported version 9|version 9
rsf_header_size_wrong.rsf|header_size:|header_size disagrees with notes_len
rsf_flags_set.rsf|flags:|unknown flags set
rsf_count_zero.rsf|count:|0 splats
rsf_count_past_end.rsf|count:|count larger than the file holds
rsf_nan_bbox.rsf|bbox_min[0]:|NaN in the bounding box
rsf_inverted_bbox.rsf|bbox_max[0]:|bbox max below min
rsf_negative_radius.rsf|radius_min:|negative radius range
rsf_radius_bomb.rsf|radius_max: 1e+07 is more than 4 times the bounding box|radius_max 1e7, every radius code 255 (a work bomb)
rsf_inf_mm_per_unit.rsf|mm_per_unit:|infinite scale
rsf_forward_not_unit.rsf|forward:|face frame not unit length
rsf_negative_face_height.rsf|face_height:|negative face height
rsf_centre_3e38.rsf|centre[0]: 3e+38 lies far outside|face centre 3e38 (rendered blank before)
rsf_face_height_1e-30.rsf|face_height: 1e-30 is implausible|face height 1e-30 (rendered blank before)
rsf_face_height_3e38.rsf|face_height: 3e+38 is implausible|face height 3e38 (rendered blank before)
rsf_lod_count_huge.rsf|lod_count:|1000 LOD levels
rsf_lods_ascending.rsf|lods[1]:|LOD table not descending
rsf_region_count_huge.rsf|region_count:|200 regions
rsf_region_m_nan.rsf|regions[0].m:|NaN roughness
rsf_region_rho_negative.rsf|regions[1].rho_s:|negative rho_s
rsf_notes_len_huge.rsf|notes_len:|notes_len 0xFFFFFFF0
rsf_notes_bad_utf8.rsf|notes:|notes not UTF-8
rsf_record_flags.rsf|splat 0:|ambient occlusion byte without the header flag
rsf_trailing_bytes.rsf|after the CRC|16 bytes after the CRC
EOF
# ---- .rsf version 2 (tests/fixtures/bad/make_bad.py, from tests/fixtures/rsf/small_v2.rsf) ----
while IFS='|' read -r file pat what; do
    bad_input "${file%.rsf}" ".rsf v2: $what" 1 "$pat" "$tmp/o.png" "$rouge" render "$bad/$file" -o "$tmp/o.png"
done <<'EOF'
rsf2_truncated_chunk.rsf|chunk 2: file ends after 100 of its|file ends 100 bytes into chunk 2
rsf2_bad_chunk_crc.rsf|chunk 1: crc: stored|one bit of chunk 1 flipped (its CRC kept)
rsf2_bad_header_crc.rsf|header crc: stored|one bit of the header flipped (its CRC kept)
rsf2_bomb.rsf|a decompression bomb?|a coded chunk claiming 1 Mi splats (16 MiB) from 512 bytes (header CRC recomputed)
EOF
bad_input rsf_bad_crc ".rsf: one payload bit flipped (CRC kept)" 1 "crc: stored" "$tmp/o.png" \
    "$rouge" render tests/fixtures/rsf/bad_crc.rsf -o "$tmp/o.png"
bad_input rsf_huge_count ".rsf: count 0xFFFFFFFF (CRC recomputed)" 1 "count:" "$tmp/o.png" \
    "$rouge" render tests/fixtures/rsf/bad_huge_count.rsf -o "$tmp/o.png"
bad_input rsf_region_out_of_table ".rsf: a splat's region 9 of 5" 1 "splat 1" "$tmp/o.png" \
    "$rouge" render tests/fixtures/rsf/bad_region.rsf -o "$tmp/o.png"
bad_input rsf_ply_given_as_face "a PLY given as the face" 1 "magic:" "$tmp/o.png" \
    "$rouge" render tests/fixtures/ply/points_le.ply -o "$tmp/o.png"
bad_input rsf_info_truncated "rouge-pack --info on a truncated .rsf" 1 "cut_payload.rsf:" - \
    "$pack" --info "$tmp/cut_payload.rsf"
bad_input rsf_ao_truncated "rouge-pack --ao on a truncated .rsf" 1 "cut_payload.rsf:" "$tmp/o.rsf" \
    "$pack" --ao "$tmp/cut_payload.rsf" -o "$tmp/o.rsf"

# ---- PLY (rouge-pack) ----
while IFS='|' read -r file pat what; do
    bad_input "${file%.ply}" "PLY: $what" 1 "$pat" "$tmp/o.rsf" "$pack" "$bad/$file" -o "$tmp/o.rsf"
done <<'EOF'
ply_wrong_magic.ply|not a PLY file|first line "plx"
ply_unknown_format.ply|unknown format|format binary_middle_endian
ply_unknown_type.ply|unknown type 'float128'|property type float128
ply_negative_count.ply|count '-2'|element vertex -2
ply_no_end_header.ply|header keyword|no end_header
ply_missing_z.ply|incomplete position|no z property
ply_zero_vertices.ply|no vertices|0 vertices
ply_nan_coordinate.ply|NaN|a NaN coordinate (ASCII)
ply_inf_coordinate.ply|infinite|an inf coordinate (ASCII)
ply_huge_double.ply|beyond float range|a double beyond float range (1e300)
ply_text_in_number.ply|not a number|text where a number belongs
ply_binary_short_body.ply|do not fit|binary body shorter than the vertex count
EOF
bad_input ply_list_count_negative "PLY: face list count -3 (uchar)" 1 "out of range for uchar" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/bad_list_count.ply -o "$tmp/o.rsf"
bad_input ply_face_index_out_of_range "PLY: face vertex index past the vertex count" 1 "vertex index 7" \
    "$tmp/o.rsf" "$pack" tests/fixtures/ply/bad_face_index.ply -o "$tmp/o.rsf"
: >"$tmp/empty.ply"
bad_input ply_empty_file "PLY: empty file" 1 "empty.ply" "$tmp/o.rsf" "$pack" "$tmp/empty.ply" -o "$tmp/o.rsf"
# A 200 kB header line: the reader must cap lines, not buffer without bound or crash.
{ echo ply; head -c 200000 /dev/zero | tr '\0' a; echo; } >"$tmp/longline.ply"
bad_input ply_endless_header_line "PLY: a 200 kB header line" 1 "longline.ply" "$tmp/o.rsf" \
    "$pack" "$tmp/longline.ply" -o "$tmp/o.rsf"
bad_input ply_dev_zero "/dev/zero as the PLY" 1 "/dev/zero" "$tmp/o.rsf" "$pack" /dev/zero -o "$tmp/o.rsf"
bad_input ply_directory "a directory as the PLY" 1 "tests/fixtures" "$tmp/o.rsf" \
    "$pack" tests/fixtures -o "$tmp/o.rsf"
bad_input pack_texture_truncated_png "--texture: a truncated PNG" 1 "truncated" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture "$bad/png_truncated.png" -o "$tmp/o.rsf"
bad_input pack_texture_huge_png "--texture: PNG header claiming 10^6 x 10^6 pixels" 1 "1000000x1000000" \
    "$tmp/o.rsf" "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture "$bad/png_huge_dimensions.png" \
    -o "$tmp/o.rsf"
bad_input pack_texture_dev_zero "--texture /dev/zero" 1 "/dev/zero" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture /dev/zero -o "$tmp/o.rsf"
bad_input import_glb_truncated "GLB cut inside its binary chunk" 1 "bad glTF 2.0 file" "$tmp/o.rsf" \
    "$pack" tests/fixtures/import/bad_truncated.glb -o "$tmp/o.rsf"
head -c 100000 tests/fixtures/import/head/head.obj >"$tmp/cut.obj"
bad_input import_obj_truncated "OBJ cut in the middle of a line (first 100000 bytes)" 1 "bad Wavefront OBJ file" \
    "$tmp/o.rsf" "$pack" "$tmp/cut.obj" -o "$tmp/o.rsf"
bad_input import_obj_not_a_model "OBJ that is a shopping list" 1 "bad Wavefront OBJ file" "$tmp/o.rsf" \
    "$pack" tests/fixtures/import/bad_not_a_model.obj -o "$tmp/o.rsf"
bad_input import_not_a_model "a PNG given as the scan" 1 "not a model rouge-pack can read" "$tmp/o.rsf" \
    "$pack" tests/fixtures/image/a_8x8.png -o "$tmp/o.rsf"
# A texture never stops a conversion (issue 24): one warning line, exit 0, the default colour instead.
warns_and_converts import_missing_texture "OBJ whose MTL names a missing texture" "which is not there" \
    "$pack" tests/fixtures/import/bad_missing_texture.obj -o "$tmp/w.rsf" --points 2000
bad_input import_texture_truncated_jpeg "--texture: a JPEG cut in half" 1 "JPEG is truncated" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture tests/fixtures/import/bad_truncated.jpg -o "$tmp/o.rsf"
bad_input import_texture_huge_jpeg "--texture: JPEG header claiming 16000 x 16000 pixels" 1 "Mpx allowed" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture tests/fixtures/import/bad_huge.jpg -o "$tmp/o.rsf"
bad_input import_texture_jpeg_bomb "--texture: 622-byte JPEG claiming 8000 x 8000 pixels" 1 "cannot hold" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture tests/fixtures/import/bad_bomb.jpg -o "$tmp/o.rsf"
# ---- hostile models through assimp (issue 23; generated here by tests/support/hostile_models.sh) ----
. tests/support/hostile_models.sh
hm="$tmp/hostile"
mkdir -p "$hm"
deep_dae "$hm/deep.dae" 100000
self_dae "$hm/self.dae"
deep_gltf "$hm/deep.gltf" 100000
deep_glb "$hm/deep.glb" 100000
deep_fbx "$hm/deep.fbx" 100000
bomb_gltf "$hm/bomb.gltf"
bomb_fbx "$hm/bomb.fbx"
# DirectX .x: a format nothing checks before assimp, so the child process has to catch the overflow.
{ printf 'xof 0303txt 0032\n'; LC_ALL=C awk 'BEGIN { for (i = 0; i < 100000; i++) printf "Frame f%d {\n", i; for (i = 0; i < 100000; i++) print "}" }'; } >"$hm/deep.x"
while IFS='|' read -r file pat what; do
    # deep.x overflows assimp's stack in the child on purpose: under `make asan` the sanitizer's own SEGV
    # handler would print its report there instead of the child dying as it does in a real build.
    saved=${ASAN_OPTIONS-}
    [ "$file" = deep.x ] && export ASAN_OPTIONS="${saved:+$saved:}handle_segv=0"
    bad_input "import_hostile_${file%%.*}_${file#*.}" "$what" 1 "$pat" "$tmp/o.rsf" \
        bounded "$pack" "$hm/$file" -o "$tmp/o.rsf"
    export ASAN_OPTIONS="$saved"
done <<'EOF2'
deep.dae|XML elements nested more than 256 deep|COLLADA: nodes nested 100000 deep (a stack overflow before)
self.dae|contains itself|COLLADA: a node that instances itself (a stack overflow before)
deep.gltf|heads a hierarchy more than 256 deep|glTF: a node chain 100000 deep (a stack overflow before)
deep.glb|heads a hierarchy more than 256 deep|GLB: a node chain 100000 deep (a stack overflow before)
deep.fbx|FBX records nested more than 256 deep|FBX (binary): records nested 100000 deep (a stack overflow before)
bomb.gltf|an instancing bomb|glTF: 10^4 nodes instancing a 10^4-triangle mesh (6.8 GB before)
bomb.fbx|a decompression bomb|FBX: 496 bytes, an array claiming 2 GiB (3.2 GB and a junk .rsf before)
deep.x|assimp crashed reading it|DirectX .x: frames nested 100000 deep (caught by the child process)
EOF2
# Files an OBJ names: a missing MTL converts with a warning; a FIFO, /dev/zero or a directory as the MTL,
# and textures outside the model's folder, are errors that never quote the file's bytes.
mo="$hm/obj"
mkdir -p "$mo/dir.mtl" "$mo/dirtex"
mkfifo "$mo/fifo.mtl" "$mo/fifo.png"
printf 'secret bytes\n' >"$hm/secret.png"
obj_naming() {  # obj_naming NAME MTL: a one-triangle OBJ with UVs naming the MTL
    printf 'mtllib %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl skin\nf 1/1 2/2 3/3\n' "$2" >"$mo/$1.obj"
}
obj_naming mtl_missing missing.mtl
obj_naming mtl_fifo fifo.mtl
obj_naming mtl_dev_zero /dev/zero
obj_naming mtl_directory dir.mtl
for t in abs:"$hm/secret.png" up:../secret.png fifo:fifo.png dev_zero:/dev/zero directory:dirtex; do
    printf 'newmtl skin\nmap_Kd %s\n' "${t#*:}" >"$mo/tex_${t%%:*}.mtl"
    obj_naming "tex_${t%%:*}" "tex_${t%%:*}.mtl"
done
while IFS='|' read -r file pat what; do
    bad_input "import_$file" "$what" 1 "$pat" "$tmp/o.rsf" bounded "$pack" "$mo/$file.obj" -o "$tmp/o.rsf" --points 100
done <<'EOF2'
mtl_fifo|fifo.mtl: not a regular file|OBJ whose MTL is a FIFO (converted untextured before)
mtl_dev_zero|'/dev/zero', outside the model's folder|OBJ whose MTL is /dev/zero (converted untextured before)
mtl_directory|dir.mtl: not a regular file|OBJ whose MTL is a directory (converted untextured before)
EOF2
# Textures the path policy refuses are not read; the model converts without them (one warning line).
while IFS='|' read -r file pat what; do
    warns_and_converts "import_$file" "$what" "$pat" bounded "$pack" "$mo/$file.obj" -o "$tmp/w.rsf" --points 100
done <<'EOF2'
tex_abs|outside the model's folder: not read|MTL naming an absolute texture path outside the model's folder
tex_up|'../secret.png', outside the model's folder: not read|MTL naming ../secret.png
tex_fifo|fifo.png: not a regular file|MTL naming a FIFO as the texture
tex_dev_zero|outside the model's folder: not read|MTL naming /dev/zero as the texture
tex_directory|dirtex: not a regular file|MTL naming a directory as the texture
EOF2
if selected robust_import_no_bytes_echoed; then
    # Even when the user allows outside paths, a warning never quotes a file the user did not name.
    bounded "$pack" "$mo/tex_up.obj" --allow-outside-paths -o "$tmp/o.rsf" --points 100 >/dev/null 2>"$tmp/err"
    rc=$?
    if [ $rc -ne 0 ] || grep -q "starts\|73 65 63" "$tmp/err" || ! grep -q "not a PNG, JPEG, BMP or TGA" "$tmp/err"; then
        echo "FAIL - robust_import_no_bytes_echoed: exit $rc: $(head -c 300 "$tmp/err")"
    else echo "ok - robust_import_no_bytes_echoed"; fi
fi
if selected robust_import_mtl_missing_warns; then
    bounded "$pack" "$mo/mtl_missing.obj" -o "$tmp/w.rsf" --points 100 -q >/dev/null 2>"$tmp/err"
    rc=$?
    if [ $rc -ne 0 ] || ! grep -q "warning: .*'.*missing.mtl', which is not there.*converted without it" "$tmp/err"; then
        echo "FAIL - robust_import_mtl_missing_warns: exit $rc: $(head -c 300 "$tmp/err")"
    else echo "ok - robust_import_mtl_missing_warns"; fi
    rm -f "$tmp/w.rsf"
fi

bad_input pack_region_map_not_png "--region-map: a PLY instead of a PNG" 1 "--region-map" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --region-map tests/fixtures/ply/points_le.ply \
    -o "$tmp/o.rsf"
bad_input pack_points_too_many "--points beyond the format's 64 Mi splats" 2 "--points" "$tmp/o.rsf" \
    "$pack" tests/fixtures/ply/mesh_st.ply --points 99999999999 -o "$tmp/o.rsf"

# ---- stroke files (rouge render --strokes) ----
while IFS='|' read -r file pat what; do
    bad_input "${file%.strokes}" "stroke file: $what" 1 "$pat" "$tmp/o.png" \
        render "$face" --strokes "$bad/$file" -o "$tmp/o.png"
done <<'EOF'
strokes_wrong_magic.strokes|line 1: not a stroke file|wrong magic line
strokes_version_9.strokes|version '9'|version 9
strokes_unknown_keyword.strokes|line 6:|unknown keyword inside a stroke
strokes_nan_sample.strokes|'nan'|NaN pointer position
strokes_huge_view.strokes|size:|view size 999999999x999999999
strokes_work_bomb.strokes|paints more than 256 face areas|a 20000-sample zigzag with a wide brush (a work bomb: > 300 s before)
strokes_unknown_cosmetic.strokes|glitter_bomb|unknown cosmetic preset
strokes_bad_pressure.strokes|pressure:|pressure 7.5
strokes_sample_outside_stroke.strokes|outside a stroke|sample before 'stroke'
EOF
bad_input strokes_dev_zero "/dev/zero as the stroke file" 1 "/dev/zero" "$tmp/o.png" \
    render "$face" --strokes /dev/zero -o "$tmp/o.png"
bad_input strokes_directory "a directory as the stroke file" 1 "tests/fixtures" "$tmp/o.png" \
    render "$face" --strokes tests/fixtures -o "$tmp/o.png"
bad_input strokes_binary "a PNG as the stroke file" 1 "a_8x8.png" "$tmp/o.png" \
    render "$face" --strokes tests/fixtures/image/a_8x8.png -o "$tmp/o.png"

# ---- look files (rouge render --look / --save-look) ----
while IFS='|' read -r file pat what; do
    bad_input "${file%.look}" "look file: $what" 1 "$pat" "$tmp/o.png" \
        render "$face" --look "$bad/$file" -o "$tmp/o.png"
done <<'EOF'
look_wrong_magic.look|not a look file|wrong magic line
look_version_9.look|version '9'|version 9
look_nan_stamp.look|'nan'|NaN stamp position
look_cosmetic_out_of_range.look|cosmetic index|stamp names cosmetic 7 of 1
look_unknown_cosmetic.look|glitter_bomb|unknown cosmetic preset
look_huge_radius.look|radius:|stamp radius 1e30
look_work_bomb.look|stamps cover 1960 face areas|2000 stamps as wide as the face (a work bomb: 121 s before)
look_negative_face_height.look|face:|face height -1
EOF
bad_input look_other_face "look file made on a face 19x smaller" 2 "another face" "$tmp/o.png" \
    render "$face" --look "$bad/look_other_face.look" -o "$tmp/o.png"
bad_input look_dev_zero "/dev/zero as the look" 1 "/dev/zero" "$tmp/o.png" \
    render "$face" --look /dev/zero -o "$tmp/o.png"
bad_input look_save_unwritable "--save-look into a missing directory" 1 "cannot write" "$tmp/o.png" \
    render "$face" --look tests/fixtures/bad/control_ok.look --save-look "$tmp/none/x.look" -o "$tmp/o.png"
mkdir -p "$tmp/dir.look"
bad_input look_save_onto_directory "--save-look onto a directory" 1 "dir.look" "$tmp/o.png" \
    render "$face" --look tests/fixtures/bad/control_ok.look --save-look "$tmp/dir.look" -o "$tmp/o.png"

# ---- output paths and the environment ----
mkdir -p "$tmp/dir.png" "$tmp/ro"
bad_input render_output_is_directory "-o naming a directory" 1 "dir.png" - \
    render "$face" -o "$tmp/dir.png"
if [ -d "$tmp/dir.png" ] && ! ls "$tmp"/dir.png.tmp* >/dev/null 2>&1; then :; else
    echo "FAIL - robust_render_output_is_directory_keeps_it: the directory was replaced or a temp file left"
fi
chmod a-w "$tmp/ro"
if touch "$tmp/ro/probe" 2>/dev/null; then
    rm -f "$tmp/ro/probe"
    selected robust_render_output_read_only_dir && echo "skip - robust_render_output_read_only_dir: running as root (permissions not enforced)"
else
    bad_input render_output_read_only_dir "-o into a read-only directory" 1 "cannot write" "$tmp/ro/o.png" \
        render "$face" -o "$tmp/ro/o.png"
fi
bad_input render_no_gles3_with_strokes "no GLES 3 (no EGL vendor), painting requested" 1 "GLES 3" "$tmp/o.png" \
    env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$rouge" render "$face" --strokes \
    tests/fixtures/strokes/cheek.strokes -o "$tmp/o.png"
bad_input view_no_display "rouge view with no display (DISPLAY, WAYLAND_DISPLAY unset)" 1 "" - \
    env -u DISPLAY -u WAYLAND_DISPLAY "$rouge" view "$face"
bad_input shaders_missing "missing shader directory at build time" 1 "cannot open shader directory" \
    "$tmp/shaders.c" "$embed" "$tmp/no_shaders" "$tmp/shaders.c"
mkdir -p "$tmp/sh"
printf '#include "gone.glsl"\nvoid main() {}\n' >"$tmp/sh/a.frag.glsl"
bad_input shaders_missing_include "a shader including a missing file" 1 "gone.glsl" "$tmp/shaders.c" \
    "$embed" "$tmp/sh" "$tmp/shaders.c"

# ---- CLI values (tests/test_cli.sh has unknown/malformed flags; these are well-formed but wrong) ----
while IFS='|' read -r name pat args; do
    # shellcheck disable=SC2086
    bad_input "cli_$name" "option: $args" 2 "$pat" "$tmp/o.png" "$rouge" render "$face" -o "$tmp/o.png" $args
done <<'EOF'
kernels_out_of_range|--kernels|--kernels 7
pipeline_unknown|--pipeline|--pipeline fast
prim_unknown|--prim|--prim hexagons
light_colour_two_components|--light-color|--light-color 1,2
background_nan|--background|--background nan,0,0
max_splats_zero|--max-splats|--max-splats 0
yaw_infinite|--yaw|--yaw inf
size_too_big|--size|--size 99999x10
size_garbage|--size|--size 64x64x64
two_faces|unexpected argument|tests/fixtures/rsf/tiny_v1.rsf
EOF
bad_input cli_view_with_output "-o given to the viewer" 2 "-o is only for" - "$rouge" view "$face" -o "$tmp/o.png"
bad_input cli_view_with_supersample "--supersample given to the viewer" 2 "--supersample is only for" - "$rouge" view "$face" --supersample 2
bad_input cli_save_look_alone "--save-look without --look or --strokes" 2 "--save-look" "$tmp/x.look" \
    render "$face" -o "$tmp/o.png" --save-look "$tmp/x.look"

# ---- rouge-imgdiff (tests/test_imgdiff.sh has missing/non-PNG/size-mismatch) ----
bad_input imgdiff_truncated_png "rouge-imgdiff: truncated PNG" 2 "truncated" - \
    "$imgdiff" "$bad/png_truncated.png" tests/fixtures/image/a_8x8.png
bad_input imgdiff_huge_png "rouge-imgdiff: PNG claiming 10^6 x 10^6 pixels" 2 "larger than" - \
    "$imgdiff" "$bad/png_huge_dimensions.png" tests/fixtures/image/a_8x8.png
bad_input imgdiff_dev_zero "rouge-imgdiff: /dev/zero" 2 "/dev/zero" - \
    "$imgdiff" /dev/zero tests/fixtures/image/a_8x8.png

# ---- lighting environments: .rse files (rouge render --env) and HDR captures (rouge-env) ----
envtool="$build/rouge-env"
envfx=tests/fixtures/env
bad_input rse_truncated ".rse: cut in half" 1 "bad_truncated.rse:" "$tmp/o.png" \
    render "$face" --env "$envfx/bad_truncated.rse" -o "$tmp/o.png"
bad_input rse_bad_crc ".rse: one texel bit flipped (CRC kept)" 1 "CRC" "$tmp/o.png" \
    render "$face" --env "$envfx/bad_crc.rse" -o "$tmp/o.png"
bad_input rse_huge_claim ".rse: claims 2048x1024 with 8 levels in 908 bytes (CRC recomputed)" 1 "bad_huge.rse:" \
    "$tmp/o.png" render "$face" --env "$envfx/bad_huge.rse" -o "$tmp/o.png"
bad_input rse_info_truncated "rouge-env --info on a truncated .rse" 1 "bad_truncated.rse:" - \
    "$envtool" --info "$envfx/bad_truncated.rse"
while IFS='|' read -r file pat what; do
    bad_input "env_tool_${file%%.*}_${file#*.}" "rouge-env: $what" 1 "$pat" "$tmp/o.rse" \
        "$envtool" "$envfx/$file" -o "$tmp/o.rse" --name x
done <<'EOF'
bad_truncated.hdr|the file ends at row|.hdr cut at 60% (run-length rows)
bad_truncated_flat.hdr|truncated|flat .hdr cut short
bad_huge.hdr|at most 8192x4096|.hdr header claiming 200000x100000
bad_garbage.hdr|not a readable Radiance|.hdr magic then garbage
bad_ratio.hdr|not a latitude-longitude map|a 64x64 .hdr (not 2:1)
bad_truncated.exr|OpenEXR:|.exr cut at 70%
bad_huge.exr|too large (max 8192)|.exr header claiming 200000x100000
bad_garbage.exr|OpenEXR:|.exr magic then garbage
bad_not_hdr.png|neither OpenEXR nor Radiance|a PNG given as the capture
EOF

# ---- inputs that once crashed a fuzz harness: the real programs must refuse them cleanly too ----
for f in "$bad"/fuzz/ply/*; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    "$pack" "$f" -o "$tmp/o.rsf" >/dev/null 2>&1
    rc=$?
    if [ "$rc" -ge 128 ]; then echo "FAIL - robust_fuzz_ply_$b: signal $((rc - 128))"; else echo "ok - robust_fuzz_ply_$b"; fi
    rm -f "$tmp/o.rsf"
done
for f in "$bad"/fuzz/rsf/*; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    "$pack" --info "$f" >/dev/null 2>&1
    rc=$?
    if [ "$rc" -ge 128 ]; then echo "FAIL - robust_fuzz_rsf_$b: signal $((rc - 128))"; else echo "ok - robust_fuzz_rsf_$b"; fi
done
for f in "$bad"/fuzz/envmap/*; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    "$build/rouge-env" "$f" -o "$tmp/o.rse" --name x >/dev/null 2>&1
    rc=$?
    if [ "$rc" -ge 128 ]; then echo "FAIL - robust_fuzz_envmap_$b: signal $((rc - 128))"; else echo "ok - robust_fuzz_envmap_$b"; fi
    rm -f "$tmp/o.rse"
done
for f in "$bad"/fuzz/import/*; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    "$pack" "$f" --points 500 -o "$tmp/o.rsf" >/dev/null 2>&1
    rc=$?
    if [ "$rc" -ge 128 ]; then echo "FAIL - robust_fuzz_import_$b: signal $((rc - 128))"; else echo "ok - robust_fuzz_import_$b"; fi
    rm -f "$tmp/o.rsf"
done
for f in "$bad"/fuzz/image/*; do
    [ -f "$f" ] || continue
    b=$(basename "$f")
    "$pack" tests/fixtures/ply/mesh_st.ply --points 100 --texture "$f" -o "$tmp/o.rsf" >/dev/null 2>&1
    rc=$?
    if [ "$rc" -ge 128 ] || [ -e "$tmp/o.rsf" ]; then echo "FAIL - robust_fuzz_image_$b: exit $rc"; else echo "ok - robust_fuzz_image_$b"; fi
    rm -f "$tmp/o.rsf"
done
for kind in strokes look; do
    for f in "$bad/fuzz/$kind"/*; do
        [ -f "$f" ] || continue
        b=$(basename "$f")
        selected "robust_fuzz_${kind}_$b" || continue
        [ -x "$rouge" ] || { echo "skip - robust_fuzz_${kind}_$b: $rouge not built"; continue; }
        opt=--$kind
        render "$face" "$opt" "$f" -o "$tmp/o.png" >/dev/null 2>&1
        rc=$?
        if [ "$rc" -ge 128 ]; then echo "FAIL - robust_fuzz_${kind}_$b: signal $((rc - 128))"; else echo "ok - robust_fuzz_${kind}_$b"; fi
        rm -f "$tmp/o.png"
    done
done

# ---- controls: the undamaged originals of the fixtures above are accepted ----
if selected robust_controls_are_accepted && [ -x "$rouge" ]; then
    if render "$face" --look "$bad/control_ok.look" --strokes "$bad/control_ok.strokes" -o "$tmp/ok.png" \
        >/dev/null 2>"$tmp/err" && [ -s "$tmp/ok.png" ] && "$pack" --info "$tiny" >/dev/null 2>&1; then
        echo "ok - robust_controls_are_accepted"
    else
        echo "FAIL - robust_controls_are_accepted: $(head -c 300 "$tmp/err")"
    fi
fi
exit 0
